// The fault detector's view of a filtered sample (see fdi_input.hpp).
#include "estimator/fdi_input.hpp"

#include <cmath>

namespace driftless::est {

FdiInput fdi_input(const Sample& s, PushStatus status, const DriftlessFilter& filter) {
  FdiInput in;
  in.t_s = s.t_s;
  in.gyro1_dps = s.gyro1_dps;
  in.gyro2_dps = s.gyro2_dps;
  const bool in_standstill =
      status == PushStatus::kAccumulating || status == PushStatus::kUpdated || status == PushStatus::kRejected;
  in.at_rest = in_standstill && std::isfinite(s.plat1_deg) && std::isfinite(s.plat2_deg);
  if (in.at_rest) {
    in.R_body_from_sensor1 = filter.body_from_sensor(1, s.plat1_deg);
    in.R_body_from_sensor2 = filter.body_from_sensor(2, s.plat2_deg);
  }
  in.bias_dps = filter.bias_dps();
  in.bias_cov_dps2 = filter.covariance_dps2();
  return in;
}

}  // namespace driftless::est
