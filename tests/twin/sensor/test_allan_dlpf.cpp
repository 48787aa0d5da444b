// The noise fit on coloured noise made by the twin's own sensor model: white noise through the
// MPU6050 DLPF (a low-pass and a fractional sample delay), as a real chip with DLPF_CFG 3..5 gives.
// N must come out as the density the model was given, within the fit's stated uncertainty.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/allan.hpp"
#include "estimator/allan_fit.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::twin {
namespace {

TEST(AllanFitTwin, WhiteNoiseThroughTheMpu6050DlpfGivesItsDensity) {
  const double fs = 200.0, density = 0.005;  // deg/s/sqrt(Hz), the datasheet value
  for (const int cfg : {3, 4, 5}) {           // 44, 21, 10 Hz: below fs/2, so the noise is filtered
    // GIVEN an ideal sensor with white noise and the DLPF only, 1000 s at 200 Hz
    SensorParams p = ideal_sensor();
    p.white_noise.enabled = true;
    p.white_noise.density_dps_rthz = Eigen::Vector3d::Constant(density);
    p.lowpass_latency.enabled = true;
    p.lowpass_latency.dlpf_cfg = cfg;
    SensorModel m(p, fs, 40 + cfg);
    std::vector<double> x(200000);
    for (std::size_t k = 0; k < x.size(); ++k) {
      x[k] = m.step(SensorTruth{static_cast<double>(k) / fs, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}).gyro_radps[0] *
             57.295779513082320876798;
    }
    est::AllanOptions o;
    o.sample_rate_hz = fs;
    const est::NoiseFit f = est::fit_noise_parameters(est::allan_deviation(x, o));
    // THEN N is recovered within 3 of its stated sigma, and the fit says the noise is low-passed
    ASSERT_TRUE(f.N.valid) << f.N.note;
    EXPECT_LT(std::fabs(f.N.value - density), 3.0 * f.N.sigma) << "cfg " << cfg << ": " << f.N.value << " +- " << f.N.sigma;
    EXPECT_LT(f.N.sigma, 0.05 * density) << "cfg " << cfg;
    EXPECT_GT(f.white_lowpass_tau_s, 0.0) << "cfg " << cfg;
  }
}

}  // namespace
}  // namespace driftless::twin
