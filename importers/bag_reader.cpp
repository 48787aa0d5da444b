// ROS 1 bags with sensor_msgs/Imu messages, through Debian's librosbag-dev (rosbag_storage).
// Built only when the configure step found it (DRIFTLESS_HAVE_ROSBAG); docs/import.md, bags.
#include <cmath>
#include <limits>
#include <string>

#include "importers/bag_records.hpp"
#include "importers/imu_reader.hpp"
#include "importers/reader_factories.hpp"
#include "importers/stamp_ns.hpp"
#include "importers/units.hpp"

#ifdef DRIFTLESS_HAVE_ROSBAG
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#endif

namespace driftless::importers {

#ifdef DRIFTLESS_HAVE_ROSBAG
namespace {

constexpr double kDegPerRad = 57.295779513082320876798;

class BagReader : public ImuReader {
 public:
  BagReader(const std::filesystem::path& path, const ImportOptions& opt);
  bool read(ImuBlock& out, std::size_t max_rows) override;
  std::string where(std::uint64_t loc) const override {
    return info_.source + ": message " + std::to_string(loc) + " on " + topic_;
  }

 private:
  std::string choose_topic(const std::vector<BagConnection>& conns, const ImportOptions& opt);
  void open_library(const std::filesystem::path& path, const ImportOptions& opt);
  void set_epoch();
  void set_epoch_direct();
  bool read_direct(ImuBlock& out, std::size_t max_rows);
  static std::int64_t ns_of(const ros::Time& t) { return static_cast<std::int64_t>(t.sec) * 1'000'000'000 + t.nsec; }
  rosbag::Bag bag_;
  std::string topic_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  std::uint64_t index_ = 0;
  double rate_scale_ = kDegPerRad;
  bool receive_time_ = false;
  std::unique_ptr<BagScan> scan_;  // the direct path (bag_records.hpp), when it gives View's messages
};

std::string BagReader::choose_topic(const std::vector<BagConnection>& conns, const ImportOptions& opt) {
  std::vector<std::string> imu, every;
  for (const BagConnection& c : conns) {
    every.push_back(c.topic + " (" + c.type + ")");
    if (c.type == "sensor_msgs/Imu") imu.push_back(c.topic);
  }
  std::string list;
  for (const auto& t : every) list += (list.empty() ? "" : ", ") + t;
  if (!opt.topic.empty()) {
    for (const auto& t : imu) {
      if (t == opt.topic) return t;
    }
    throw ImportError(info_.source + ": --topic " + opt.topic + ": no sensor_msgs/Imu topic of that name (the bag has: " +
                      (list.empty() ? std::string("no topics") : list) + ")");
  }
  if (imu.size() == 1) {
    info_.assumptions.push_back("topic " + imu[0] + " (the bag's only sensor_msgs/Imu topic)");
    return imu[0];
  }
  throw ImportError(info_.source + (imu.empty() ? ": no sensor_msgs/Imu topic (the bag has: " + list + ")"
                                                : ": several sensor_msgs/Imu topics: give --topic (the bag has: " + list + ")"));
}

// the first message's stamp (or receive time when the stamps are zero), floored to whole seconds
void BagReader::set_epoch() {
  if (it_ == view_->end()) return;
  try {
    const auto m = it_->instantiate<sensor_msgs::Imu>();
    if (!m) return;
    receive_time_ = m->header.stamp.isZero();
    if (receive_time_) info_.assumptions.push_back("header stamps are zero: the bag's receive times are used");
    info_.epoch_s = epoch_s_of(ns_of(receive_time_ ? it_->getTime() : m->header.stamp));
  } catch (const std::exception& e) {
    throw ImportError(where(1) + ": cannot read (" + e.what() + ")");
  }
}

// rosbag's own reader: every bag it can open (compressed, chunks out of time order, ...)
void BagReader::open_library(const std::filesystem::path& path, const ImportOptions& opt) {
  try {
    bag_.open(path.string(), rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw ImportError(info_.source + ": not a readable ROS 1 bag (" + e.what() + ")");
  }
  std::vector<BagConnection> conns;
  for (const rosbag::ConnectionInfo* c : rosbag::View(bag_).getConnections()) conns.push_back({c->id, c->topic, c->datatype});
  topic_ = choose_topic(conns, opt);
  view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topic_));
  it_ = view_->begin();
  info_.rows_estimate = view_->size();
  set_epoch();
}

void BagReader::set_epoch_direct() {
  const BagImu* m = nullptr;
  try {
    m = scan_->peek();
  } catch (const std::runtime_error& e) {
    throw ImportError(where(1) + ": cannot read (" + e.what() + ")");
  }
  if (m == nullptr) return;
  receive_time_ = m->stamp_ns == 0;
  if (receive_time_) info_.assumptions.push_back("header stamps are zero: the bag's receive times are used");
  info_.epoch_s = epoch_s_of(receive_time_ ? m->receive_ns : m->stamp_ns);
}

BagReader::BagReader(const std::filesystem::path& path, const ImportOptions& opt) {
  info_.source = path.string();
  info_.format = Format::kBag;
  // the direct path when the bag allows it (same messages, same order), else librosbag
  std::string why;
  std::optional<std::vector<BagConnection>> conns;
  try {
    conns = BagScan::connections(path, why);
    if (conns) {
      topic_ = choose_topic(*conns, opt);
      scan_ = BagScan::open(path, topic_, why);
    }
  } catch (const std::runtime_error&) {
    scan_.reset();  // a damaged index: librosbag's verdict below
  }
  if (scan_) {
    info_.rows_estimate = scan_->count();
    set_epoch_direct();
  } else {
    info_.assumptions.clear();  // the topic is chosen again from librosbag's view
    open_library(path, opt);
  }
  info_.has_time = true;
  if (!opt.units.empty()) {
    rate_scale_ = parse_rate_unit(opt.units, "--units").scale;
    info_.assumptions.push_back("angular_velocity in " + opt.units + " (as given; sensor_msgs/Imu defines rad/s)");
  } else {
    info_.assumptions.push_back("angular_velocity in rad/s, linear_acceleration in m/s^2 (sensor_msgs/Imu)");
  }
  for (int k = 0; k < 3; ++k) info_.channels.push_back({std::string("angular_velocity.") + "xyz"[k], Quantity::kRate, k});
  for (int k = 0; k < 3; ++k) info_.channels.push_back({std::string("linear_acceleration.") + "xyz"[k], Quantity::kAccel, k});
}

// the messages converted where the scan decoded them, into the block's arrays as they are (sized
// once: no zero-filling of what is written next)
bool BagReader::read_direct(ImuBlock& out, std::size_t max_rows) {
  out.values.resize(6);
  const std::size_t room = static_cast<std::size_t>(std::min<std::uint64_t>(max_rows, info_.rows_estimate - index_));
  out.t_s.resize(room);
  out.loc.resize(room);
  for (auto& v : out.values) v.resize(room);
  std::size_t n = 0;
  try {
    const BagImu* got = nullptr;
    for (std::size_t k; n < room && (k = scan_->take(room - n, got)) > 0;) {
      for (const BagImu* m = got; m != got + k; ++m) {
        out.t_s[n] = seconds_since(receive_time_ ? m->receive_ns : m->stamp_ns, info_.epoch_s);
        for (std::size_t j = 0; j < 3; ++j) {
          out.values[j][n] = m->w[j] * rate_scale_;
          out.values[3 + j][n] = m->a[j];
        }
        out.loc[n++] = ++index_;
      }
    }
  } catch (const std::runtime_error& e) {
    throw ImportError(where(index_ + 1) + ": cannot read (" + e.what() + ")");
  }
  out.t_s.resize(n);
  out.loc.resize(n);
  for (auto& v : out.values) v.resize(n);
  return n > 0;
}

bool BagReader::read(ImuBlock& out, std::size_t max_rows) {
  if (scan_) return read_direct(out, max_rows);
  out.clear();
  out.values.resize(6);
  try {
    for (; it_ != view_->end() && out.rows() < max_rows; ++it_) {
      ++index_;
      const auto m = it_->instantiate<sensor_msgs::Imu>();
      if (!m) throw ImportError(where(index_) + ": not a sensor_msgs/Imu message");
      out.t_s.push_back(seconds_since(ns_of(receive_time_ ? it_->getTime() : m->header.stamp), info_.epoch_s));
      const double w[3] = {m->angular_velocity.x, m->angular_velocity.y, m->angular_velocity.z};
      const double a[3] = {m->linear_acceleration.x, m->linear_acceleration.y, m->linear_acceleration.z};
      for (int k = 0; k < 3; ++k) {
        out.values[static_cast<std::size_t>(k)].push_back(w[k] * rate_scale_);
        out.values[static_cast<std::size_t>(3 + k)].push_back(a[k]);
      }
      out.loc.push_back(index_);
    }
  } catch (const ImportError&) {
    throw;
  } catch (const std::exception& e) {
    throw ImportError(where(index_) + ": cannot read (" + e.what() + ")");
  }
  return out.rows() > 0;
}

}  // namespace

bool bag_support() { return true; }

std::unique_ptr<ImuReader> make_bag_reader(const std::filesystem::path& path, const ImportOptions& opt) {
  return std::make_unique<BagReader>(path, opt);
}

#else

bool bag_support() { return false; }

std::unique_ptr<ImuReader> make_bag_reader(const std::filesystem::path& path, const ImportOptions&) {
  throw ImportError(path.string() + ": this build reads no ROS bags: install librosbag-dev (scripts/setup.sh does) "
                    "and configure again");
}

#endif

}  // namespace driftless::importers
