// ROS 1 bags: written in the test with librosbag from the real recording, read back through the
// importer; topic choice, receive times, and files that are no bag. C++17 (ROS 1 headers).
#include <cmath>

#include <gtest/gtest.h>

#include "import_fixture.hpp"

#ifdef DRIFTLESS_HAVE_ROSBAG
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Float64.h>

#include "importers/bag_records.hpp"
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

// the same messages in two bags: chunks of `chunk_bytes`, uncompressed or bz2
void write_pair(const std::filesystem::path& plain, const std::filesystem::path& bz2, int n) {
  rosbag::Bag a(plain.string(), rosbag::bagmode::Write), b(bz2.string(), rosbag::bagmode::Write);
  a.setChunkThreshold(16 * 1024);
  b.setChunkThreshold(16 * 1024);
  b.setCompression(rosbag::compression::BZ2);
  for (int i = 0; i < n; ++i) {
    const std::vector<double> r = {0, 0.01 * (i % 7), -0.02, 1.0 + 1e-3 * (i % 11), 0.1 * (i % 13), -0.3, 0.5 + 1e-4 * i, 25};
    // receive times: steps of 2.5 ms, every 50th message 1 ms before its predecessor, every
    // 70th at its predecessor's time (View orders by time, stably)
    const double t = 100.0 + 0.0025 * i - (i % 50 == 49 ? 0.0035 : 0.0) - (i % 70 == 69 ? 0.0025 : 0.0);
    sensor_msgs::Imu m = message(r, 0.0025 * i, false);
    m.header.frame_id = std::string(static_cast<std::size_t>(i % 5), 'f');  // headers of varying length
    for (rosbag::Bag* bag : {&a, &b}) {
      bag->write("/imu0", ros::Time(t), m);
      if (i % 3 == 0) {
        std_msgs::Float64 other;
        other.data = i;
        bag->write("/temperature", ros::Time(t), other);
      }
    }
  }
}

// GIVEN a bag written uncompressed (read directly, record by record) and the same messages
// compressed (read by librosbag), with receive times out of order inside chunks, ties, varying
// header lengths and a second topic, WHEN both are imported, THEN every sample, stamp and
// message number is the same, in the same order
TEST(BagImport, DirectReadingGivesLibrosbagsMessagesInItsOrder) {
  const auto dir = scratch("bag_direct");
  write_pair(dir / "plain.bag", dir / "bz2.bag", 3000);
  std::string why;
  ASSERT_NE(BagScan::open(dir / "plain.bag", "/imu0", why), nullptr) << why;
  EXPECT_EQ(BagScan::open(dir / "bz2.bag", "/imu0", why), nullptr);
  EXPECT_EQ(why, "compressed chunks (bz2)");
  EXPECT_EQ(BagScan::open(dir / "plain.bag", "/temperature", why), nullptr);
  EXPECT_EQ(why, "/temperature carries std_msgs/Float64");
  auto direct = open_imu(dir / "plain.bag", {});
  auto library = open_imu(dir / "bz2.bag", {});
  EXPECT_EQ(direct->info().rows_estimate, 3000u);
  EXPECT_EQ(direct->info().epoch_s, library->info().epoch_s);
  EXPECT_EQ(direct->info().assumptions, library->info().assumptions);
  const Table a = read_all(*direct, 777), b = read_all(*library, 1000);
  ASSERT_EQ(a.t.size(), 3000u);
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.ch, b.ch);
  EXPECT_EQ(a.loc, b.loc);
  // (the order is by receive time: message 49 came before 48)
  EXPECT_NEAR(a.t[48], 1000.0 + 0.0025 * 49 - 1000, 1e-9);
}

// GIVEN a bag cut short inside its last chunk (no index: librosbag refuses it), WHEN imported,
// THEN the error names the file
TEST(BagImport, TruncatedBagIsRefusedNamingTheFile) {
  const auto dir = scratch("bag_cut");
  write_pair(dir / "plain.bag", dir / "bz2.bag", 500);
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
