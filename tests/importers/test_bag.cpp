// ROS 1 bags: written in the test with librosbag from the real recording, read back through the
// importer; uncompressed, bz2 and lz4 chunks; topic choice, receive times, and files that are no
// bag. C++17 (ROS 1 headers).
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "import_fixture.hpp"

#ifdef DRIFTLESS_HAVE_ROSBAG
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include "importers/bag_records.hpp"
#include "importers/stamp_ns.hpp"
#endif

namespace driftless::importers::test {
namespace {

constexpr double kDegPerRad = 57.295779513082320876798;
constexpr double kG = 9.80665;

#ifdef DRIFTLESS_HAVE_ROSBAG

sensor_msgs::Imu message(const std::vector<double>& r, double t_s, bool zero_stamp) {
  sensor_msgs::Imu m;
  m.header.stamp = zero_stamp ? ros::Time() : ros::Time(1000.0 + t_s);
  m.header.frame_id = "imu";
  m.angular_velocity.x = r[4] / kDegPerRad;
  m.angular_velocity.y = r[5] / kDegPerRad;
  m.angular_velocity.z = r[6] / kDegPerRad;
  m.linear_acceleration.x = r[1] * kG;
  m.linear_acceleration.y = r[2] * kG;
  m.linear_acceleration.z = r[3] * kG;
  return m;
}

TEST(BagImport, RealRecordingWrittenAsImuMessagesReadsBack) {
  DRIFTLESS_NEED_REALDATA();
  ASSERT_TRUE(bag_support());
  // GIVEN the sunsided recording as sensor_msgs/Imu on /imu0, plus a camera-info-like other topic
  const Csv csv = plain_csv(sunsided_10min());
  const auto dir = scratch("bag");
  {
    rosbag::Bag bag((dir / "imu.bag").string(), rosbag::bagmode::Write);
    for (const auto& r : csv.rows) bag.write("/imu0", ros::Time(1000.0 + r[0]), message(r, r[0], false));
  }
  // WHEN it is opened with detection
  auto rd = open_imu(dir / "imu.bag", {});
  const Table t = read_all(*rd, 10000);
  // THEN the only Imu topic is taken, rates come back in deg/s, stamps from the headers
  EXPECT_EQ(rd->info().format, Format::kBag);
  ASSERT_EQ(t.t.size(), csv.rows.size());
  // (times count from the epoch, the first stamp floored to whole seconds)
  EXPECT_EQ(rd->info().epoch_s, 1000);
  for (std::size_t i = 0; i < csv.rows.size(); i += 1013) {
    EXPECT_NEAR(t.t[i], csv.rows[i][0], 1e-9);
    EXPECT_NEAR(t.ch[0][i], csv.rows[i][4], 1e-12);
    EXPECT_NEAR(t.ch[5][i], csv.rows[i][3] * kG, 1e-12);
    EXPECT_EQ(t.loc[i], i + 1);
  }
}

// the same messages in three bags: chunks of 16 kB, uncompressed, bz2 and lz4
void write_bags(const std::filesystem::path& dir, int n) {
  rosbag::Bag a((dir / "plain.bag").string(), rosbag::bagmode::Write), b((dir / "bz2.bag").string(), rosbag::bagmode::Write),
      c((dir / "lz4.bag").string(), rosbag::bagmode::Write);
  for (rosbag::Bag* bag : {&a, &b, &c}) bag->setChunkThreshold(16 * 1024);
  b.setCompression(rosbag::compression::BZ2);
  c.setCompression(rosbag::compression::LZ4);
  for (int i = 0; i < n; ++i) {
    const std::vector<double> r = {0, 0.01 * (i % 7), -0.02, 1.0 + 1e-3 * (i % 11), 0.1 * (i % 13), -0.3, 0.5 + 1e-4 * i, 25};
    // receive times: steps of 2.5 ms, every 50th message 1 ms before its predecessor, every
    // 70th at its predecessor's time (View orders by time, stably)
    const double t = 100.0 + 0.0025 * i - (i % 50 == 49 ? 0.0035 : 0.0) - (i % 70 == 69 ? 0.0025 : 0.0);
    sensor_msgs::Imu m = message(r, 0.0025 * i, false);
    m.header.frame_id = std::string(static_cast<std::size_t>(i % 5), 'f');  // headers of varying length
    for (rosbag::Bag* bag : {&a, &b, &c}) {
      bag->write("/imu0", ros::Time(t), m);
      if (i % 3 == 0) {
        std_msgs::Float64 other;
        other.data = i;
        bag->write("/temperature", ros::Time(t), other);
      }
    }
  }
}

// GIVEN the same messages uncompressed, bz2 and lz4 (every chunk read directly, the compressed
// ones undone here), with receive times out of order inside chunks, ties, varying header lengths
// and a second topic, WHEN they are imported, THEN every sample, stamp and message number is the
// same, in rosbag::View's order (read here through librosbag itself)
TEST(BagImport, DirectReadingGivesLibrosbagsMessagesInItsOrderCompressedOrNot) {
  const auto dir = scratch("bag_direct");
  write_bags(dir, 3000);
  std::string why;
  for (const char* name : {"plain.bag", "bz2.bag", "lz4.bag"}) {
    EXPECT_NE(BagScan::open(dir / name, "/imu0", why), nullptr) << name << ": " << why;
  }
  EXPECT_EQ(BagScan::open(dir / "plain.bag", "/temperature", why), nullptr);
  EXPECT_EQ(why, "/temperature carries std_msgs/Float64");
  // librosbag's view of the plain bag: the stamps' ns and the x rate in rad/s, in its order
  std::vector<std::int64_t> view_ns;
  std::vector<double> view_wx;
  {
    rosbag::Bag bag((dir / "plain.bag").string(), rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& mi : rosbag::View(bag, rosbag::TopicQuery("/imu0"))) {
      const auto m = mi.instantiate<sensor_msgs::Imu>();
      view_ns.push_back(static_cast<std::int64_t>(m->header.stamp.sec) * 1'000'000'000 + m->header.stamp.nsec);
      view_wx.push_back(m->angular_velocity.x);
    }
  }
  auto plain = open_imu(dir / "plain.bag", {});
  const Table a = read_all(*plain, 777);
  ASSERT_EQ(a.t.size(), 3000u);
  ASSERT_EQ(view_ns.size(), 3000u);
  EXPECT_EQ(plain->info().rows_estimate, 3000u);
  for (std::size_t i = 0; i < a.t.size(); ++i) {
    ASSERT_EQ(a.t[i], seconds_since(view_ns[i], plain->info().epoch_s)) << i;
    ASSERT_EQ(a.ch[0][i], view_wx[i] * kDegPerRad) << i;
    ASSERT_EQ(a.loc[i], i + 1);
  }
  for (const char* name : {"bz2.bag", "lz4.bag"}) {
    auto rd = open_imu(dir / name, {});
    EXPECT_EQ(rd->info().epoch_s, plain->info().epoch_s);
    EXPECT_EQ(rd->info().assumptions, plain->info().assumptions);
    const Table b = read_all(*rd, 1000);
    EXPECT_EQ(a.t, b.t) << name;
    EXPECT_EQ(a.ch, b.ch) << name;
    EXPECT_EQ(a.loc, b.loc) << name;
  }
  // (the order is by receive time: message 49 came before 48)
  EXPECT_NEAR(a.t[48], 1000.0 + 0.0025 * 49 - 1000, 1e-9);
}

// GIVEN a bz2 and an lz4 bag with a chunk's compressed bytes overwritten, WHEN imported, THEN
// the error names the file, the message being read and the chunk's byte
TEST(BagImport, DamagedCompressedChunkIsRefusedNamingFileAndChunk) {
  const auto dir = scratch("bag_damaged");
  write_bags(dir, 500);
  for (const char* name : {"bz2.bag", "lz4.bag"}) {
    // the first chunk record starts at byte 4117, after the 13-byte magic line and the bag header
    // record (librosbag pads it to 4104 bytes); its compressed data begin within 100 bytes
    std::fstream f(dir / name, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(4117 + 300);
    const std::string junk(200, '\x5a');
    f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
    f.close();
    try {
      auto rd = open_imu(dir / name, {});
      read_all(*rd);
      FAIL() << name << ": a damaged chunk was read";
    } catch (const ImportError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(std::string(name) + ": message 1"), std::string::npos) << msg;
      EXPECT_NE(msg.find(std::string(name) + ": byte 4117: "), std::string::npos) << msg;
    }
  }
}

// GIVEN a bag cut short inside its last chunk (no index: librosbag refuses it), WHEN imported,
// THEN the error names the file
TEST(BagImport, TruncatedBagIsRefusedNamingTheFile) {
  const auto dir = scratch("bag_cut");
  write_bags(dir, 500);
  const auto size = std::filesystem::file_size(dir / "plain.bag");
  std::filesystem::copy_file(dir / "plain.bag", dir / "cut.bag", std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(dir / "cut.bag", size / 2);
  try {
    auto rd = open_imu(dir / "cut.bag", {});
    read_all(*rd);
    FAIL() << "a truncated bag was read";
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.bag"), std::string::npos) << e.what();
  }
}

TEST(BagImport, TopicsAreChosenOrListed) {
  const auto dir = scratch("bag_topics");
  std::vector<double> r = {0, 0, 0, 1, 0.1, 0.2, 0.3, 25};
  {
    rosbag::Bag bag((dir / "two.bag").string(), rosbag::bagmode::Write);
    for (int i = 0; i < 50; ++i) {
      bag.write("/imu0", ros::Time(10.0 + 0.01 * i), message(r, 0.01 * i, false));
      bag.write("/imu1", ros::Time(10.0 + 0.01 * i), message(r, 0.01 * i, true));
    }
  }
  // two Imu topics: refused with both named
  try {
    open_imu(dir / "two.bag", {});
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("/imu0 (sensor_msgs/Imu)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("give --topic"), std::string::npos);
  }
  // --topic picks one; zero header stamps fall back to the receive times, and say so
  ImportOptions o;
  o.topic = "/imu1";
  auto rd = open_imu(dir / "two.bag", o);
  const Table t = read_all(*rd);
  ASSERT_EQ(t.t.size(), 50u);
  EXPECT_EQ(rd->info().epoch_s, 10);
  EXPECT_NEAR(t.t[3], 0.03, 1e-9);
  bool said = false;
  for (const auto& a : rd->info().assumptions) said = said || a.find("receive times") != std::string::npos;
  EXPECT_TRUE(said);
  o.topic = "/camera";
  EXPECT_THROW(open_imu(dir / "two.bag", o), ImportError);
  // a file that only claims to be a bag
  write_text(dir / "fake.bag", "#ROSBAG V2.0\nnot really");
  try {
    open_imu(dir / "fake.bag", {});
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("fake.bag: not a readable ROS 1 bag"), std::string::npos) << e.what();
  }
}

#else

TEST(BagImport, BuildWithoutRosbagSaysSo) {
  const auto dir = scratch("nobag");
  write_text(dir / "x.bag", "#ROSBAG V2.0\n");
  EXPECT_FALSE(bag_support());
  try {
    open_imu(dir / "x.bag", {});
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("librosbag-dev"), std::string::npos);
  }
}

#endif

}  // namespace
}  // namespace driftless::importers::test
