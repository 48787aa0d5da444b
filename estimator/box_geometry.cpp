#include "estimator/box_geometry.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "estimator/geometry.hpp"
#include "estimator/log.hpp"

namespace driftless::est {

void BoxGeometry::validate() {
  auto axis = [](Eigen::Vector3d& a, const char* name) {
    if (!a.allFinite() || !(a.norm() > 1e-9)) {
      throw std::invalid_argument(std::string("box geometry: ") + name + " must be a non-zero vector (box axes)");
    }
    a.normalize();
  };
  axis(hinge1_axis, "hinge1_axis");
  axis(hinge2_axis, "hinge2_axis");
  if (!std::isnan(sample_rate_hz) && !(sample_rate_hz > 0.0 && std::isfinite(sample_rate_hz))) {
    throw std::invalid_argument("box geometry: sample_rate_hz must be > 0 Hz, got " + std::to_string(sample_rate_hz));
  }
  if (!std::isnan(latitude_deg) && !(std::fabs(latitude_deg) <= 90.0)) {
    throw std::invalid_argument("box geometry: latitude_deg must be in [-90, 90] deg, got " +
                                std::to_string(latitude_deg));
  }
  if (!(flip_angle_deg > 0.0 && flip_angle_deg <= 180.0)) {
    throw std::invalid_argument("box geometry: flip_angle_deg must be in (0, 180] deg, got " +
                                std::to_string(flip_angle_deg));
  }
}

double eq5_position_deg(int pattern, int sensor, double flip_angle_deg) {
  const geo::FlipSigns s = geo::flip_cycle_at(pattern);
  return flip_angle_deg * (sensor == 1 ? s.plat1 : s.plat2);
}

int eq5_pattern_of(double plat1_deg, double plat2_deg) { return geo::flip_cycle_index(plat1_deg, plat2_deg); }

BoxGeometry box_geometry_from_metadata(const log::Metadata& meta) {
  BoxGeometry g;
  g.hinge1_axis = meta.hinge1_axis();
  g.hinge2_axis = meta.hinge2_axis();
  g.sample_rate_hz = meta.sample_rate_hz();
  g.latitude_deg = meta.latitude_deg();
  g.flip_angle_deg = meta.get_number("flip_angle_deg", meta.get_number("end_stop_deg", 90.0));
  g.validate();
  return g;
}

}  // namespace driftless::est
