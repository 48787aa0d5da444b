// ROS 1 bag v2.0 records read directly (http://wiki.ros.org/Bags/Format/2.0): the index at the
// file's end (connections, chunk infos), then the chunks in file order, decoding only the
// sensor_msgs/Imu messages of one connection. No ROS library: librosbag builds a time-sorted
// index of every message at open and deserialises each message's header map, 1.2 us a message;
// this reads a record in a few tens of ns. Bags with the topic on one connection, their
// chunks uncompressed, bz2 or lz4 (undone here with libbz2 / liblz4), are read this way
// (BagScan::open says why not); the reader falls back to librosbag otherwise. The messages
// and their order are those of rosbag::View.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace driftless::importers {

/// One sensor_msgs/Imu message: receive time and header stamp (ns since 1970), rates (as
/// stored: rad/s) and accelerations (m/s^2).
struct BagImu {
  std::int64_t receive_ns = 0;
  std::int64_t stamp_ns = 0;
  double w[3] = {0, 0, 0};
  double a[3] = {0, 0, 0};
};

/// A bag's connection (one topic and type).
struct BagConnection {
  std::uint32_t id = 0;
  std::string topic;
  std::string type;
};

class BagScan {
 public:
  /// A chunk's compression (bz2 and lz4 read when the build found libbz2 / liblz4).
  enum class Codec : std::uint8_t { kNone, kBz2, kLz4 };
  /// Reads the bag's index. Returns nothing, with `why` set, when the direct path cannot give
  /// rosbag::View's messages in its order: chunks compressed in a way this build cannot undo, no index (an unfinished bag), the
  /// topic on several connections, chunks overlapping in time over more than 4 M messages. Throws std::runtime_error on a
  /// damaged file.
  static std::unique_ptr<BagScan> open(const std::filesystem::path& path, const std::string& topic, std::string& why);
  ~BagScan();
  BagScan(const BagScan&) = delete;
  BagScan& operator=(const BagScan&) = delete;

  /// The connections in a bag's index, in id order; nothing, with `why` set, when the bag cannot
  /// be read directly (not format 2.0, no index).
  static std::optional<std::vector<BagConnection>> connections(const std::filesystem::path& path, std::string& why);
  /// The next message without taking it (nullptr at the end).
  const BagImu* peek();
  /// Up to max messages of the topic, in rosbag::View order (receive time, then file order),
  /// where they were decoded (no copy): `first` points at them until the next call; returns how
  /// many (0 at the end). Throws std::runtime_error naming the record on a damaged one. (No
  /// std::span: the bag reader compiles as C++17.)
  std::size_t take(std::size_t max, const BagImu*& first);
  /// Messages of the topic in the whole bag (from the chunk infos).
  std::uint64_t count() const { return count_; }

 private:
  struct Chunk {
    std::uint64_t pos = 0;
    std::uint64_t start_ns = 0, end_ns = 0;
    std::uint32_t ours = 0;  // messages of our connection in it
    Codec codec = Codec::kNone;
    std::uint32_t plain_size = 0;  // bytes, uncompressed (compressed chunks)
  };
  BagScan() = default;
  // opens the file and reads the bag header: the index's position and size (false: why set)
  bool start(const std::filesystem::path& path, std::string& why);
  std::vector<BagConnection> read_connections();
  void load_group();
  void load_chunk(const Chunk& c);
  std::uint64_t index_pos_ = 0;
  std::uint32_t conn_count_ = 0, chunk_count_ = 0;
  std::FILE* file_ = nullptr;
  std::string path_;
  std::uint32_t conn_ = 0;
  std::vector<Chunk> chunks_;
  std::size_t next_chunk_ = 0;
  std::uint64_t count_ = 0;
  std::vector<BagImu> pending_;  // the current chunk's messages not yet handed out
  std::size_t pending_pos_ = 0;
  std::vector<char> buf_;
  std::vector<char> plain_;  // a compressed chunk's data, uncompressed
};

}  // namespace driftless::importers
