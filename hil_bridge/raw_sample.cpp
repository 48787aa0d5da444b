#include "hil_bridge/raw_sample.hpp"

namespace driftless::hil {

using namespace mpu6050;

int fill_from_raw(int sensor, const RawRecord& r, int gyro_fs_sel, int accel_fs_sel, Sample& s) {
  const double glsb = gyro_lsb_per_dps(gyro_fs_sel);
  const double alsb = accel_lsb_per_g(accel_fs_sel);
  Eigen::Vector3d& g = sensor == 0 ? s.gyro1_dps : s.gyro2_dps;
  Eigen::Vector3d& a = sensor == 0 ? s.accel1_mps2 : s.accel2_mps2;
  int mask = 0;
  for (int i = 0; i < 3; ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (is_saturated(r.gyro[u])) {
      g[i] = kNaN;  // a clipped reading is not a measurement of the rate
      mask |= 1 << i;
    } else {
      g[i] = r.gyro[u] / glsb;
    }
    a[i] = r.accel[u] / alsb * kStandardGravityMps2;
  }
  (sensor == 0 ? s.temp1_c : s.temp2_c) = temp_c_from_raw(r.temp);
  return mask;
}

std::string SaturationTracker::update(int sensor, int mask, int gyro_fs_sel) {
  const auto i = static_cast<std::size_t>(sensor);
  std::string msg;
  if (mask != 0) ++count_[i];
  if (mask != 0 && mask_[i] == 0) {
    std::string axes;
    for (int a = 0; a < 3; ++a) {
      if (mask & (1 << a)) axes += "xyz"[a];
    }
    msg = "sensor " + std::to_string(sensor + 1) + " gyro " + axes + " saturated at +-" +
          std::to_string(static_cast<int>(gyro_full_scale_dps(gyro_fs_sel))) +
          " deg/s full scale: saturated axes are written empty";
  } else if (mask == 0 && mask_[i] != 0) {
    msg = "sensor " + std::to_string(sensor + 1) + " gyro back in range after " +
          std::to_string(count_[i]) + " saturated samples";
    count_[i] = 0;
  }
  mask_[i] = mask;
  return msg;
}

}  // namespace driftless::hil
