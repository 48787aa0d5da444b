// The format readers behind open_imu(). Internal to importers/.
#pragma once

#include <filesystem>
#include <memory>

#include "importers/imu_reader.hpp"

namespace driftless::importers {

std::unique_ptr<ImuReader> make_text_reader(const std::filesystem::path& path, const ImportOptions& opt, bool euroc);
std::unique_ptr<ImuReader> make_npy_reader(const std::filesystem::path& path, const ImportOptions& opt);
/// Throws ImportError when this build has no ROS bag support.
std::unique_ptr<ImuReader> make_bag_reader(const std::filesystem::path& path, const ImportOptions& opt);

}  // namespace driftless::importers
