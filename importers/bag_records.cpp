#include "importers/bag_records.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string_view>

#ifdef DRIFTLESS_HAVE_BZ2
#include <bzlib.h>
#endif
#ifdef DRIFTLESS_HAVE_LZ4
#include <lz4frame.h>
#endif

namespace driftless::importers {
namespace {

constexpr std::string_view kMagic = "#ROSBAG V2.0\n";
constexpr std::uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpChunk = 0x05, kOpChunkInfo = 0x06,
                       kOpConnection = 0x07;
// a sensor_msgs/Imu after its header: orientation (4), its covariance (9), angular_velocity (3),
// its covariance (9), linear_acceleration (3), its covariance (9), float64 each
constexpr std::size_t kImuBodyBytes = 37 * 8;
constexpr std::size_t kRateOffset = 13 * 8, kAccelOffset = 25 * 8;
// chunks that overlap in time are sorted together: at most this many messages (~180 MB)
constexpr std::uint64_t kMaxGroupMessages = 1u << 22;

template <class T>
T load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);  // the format is little-endian, as is every machine this builds on
  return v;
}

std::int64_t ns_of_time(std::uint64_t t) {  // a bag time: uint32 sec, then uint32 nsec
  return static_cast<std::int64_t>(t & 0xffffffffu) * 1'000'000'000 + static_cast<std::int64_t>(t >> 32);
}

// one record's header fields: name=value pairs, each behind its uint32 length
struct Fields {
  std::string_view all;
  std::string_view get(std::string_view name) const {
    std::size_t p = 0;
    while (p + 4 <= all.size()) {
      const auto len = load<std::uint32_t>(all.data() + p);
      if (len > all.size() - p - 4) break;
      const std::string_view f = all.substr(p + 4, len);
      const auto eq = f.find('=');
      if (eq != std::string_view::npos && f.substr(0, eq) == name) return f.substr(eq + 1);
      p += 4 + len;
    }
    return {};
  }
  bool has(std::string_view name) const { return get(name).data() != nullptr; }
  std::uint8_t op() const {
    const auto v = get("op");
    return v.size() == 1 ? static_cast<std::uint8_t>(v[0]) : 0;
  }
  template <class T>
  T num(std::string_view name, const std::string& where) const {
    const auto v = get(name);
    if (v.size() != sizeof(T)) throw std::runtime_error(where + ": record field '" + std::string(name) + "' missing");
    return load<T>(v.data());
  }
};

// a message data record's header in one pass: op 0x02, its connection and receive time (false:
// another record, or a field missing)
bool message_fields(std::string_view all, std::uint32_t& conn, std::uint64_t& time) {
  bool op = false, have_conn = false, have_time = false;
  for (std::size_t p = 0; p + 4 <= all.size();) {
    const auto len = load<std::uint32_t>(all.data() + p);
    if (len > all.size() - p - 4) break;
    const char* f = all.data() + p + 4;
    if (len == 4 && std::memcmp(f, "op=", 3) == 0) {
      if (static_cast<std::uint8_t>(f[3]) != kOpMessage) return false;
      op = true;
    } else if (len == 9 && std::memcmp(f, "conn=", 5) == 0) {
      conn = load<std::uint32_t>(f + 5);
      have_conn = true;
    } else if (len == 13 && std::memcmp(f, "time=", 5) == 0) {
      time = load<std::uint64_t>(f + 5);
      have_time = true;
    }
    p += 4 + len;
  }
  return op && have_conn && have_time;
}

// reads whole records from a FILE: header and data into `buf` (header first)
struct RecordReader {
  std::FILE* f;
  const std::string& path;
  std::vector<char>& buf;
  std::uint32_t header_len = 0, data_len = 0;
  bool read_at(std::uint64_t pos, bool with_data) {
    if (std::fseek(f, static_cast<long>(pos), SEEK_SET) != 0) fail(pos, "cannot seek");
    return read_next(pos, with_data);
  }
  bool read_next(std::uint64_t pos, bool with_data) {
    char len[4];
    if (std::fread(len, 1, 4, f) != 4) return false;
    header_len = load<std::uint32_t>(len);
    if (header_len > (64u << 20)) fail(pos, "record header of " + std::to_string(header_len) + " bytes");
    buf.resize(header_len + 4);
    if (std::fread(buf.data(), 1, header_len + 4, f) != header_len + 4) fail(pos, "truncated record");
    data_len = load<std::uint32_t>(buf.data() + header_len);
    if (with_data) {
      buf.resize(header_len + data_len);
      if (std::fread(buf.data() + header_len, 1, data_len, f) != data_len) fail(pos, "truncated record data");
    } else if (std::fseek(f, static_cast<long>(data_len), SEEK_CUR) != 0) {
      fail(pos, "cannot seek");
    }
    return true;
  }
  Fields fields() const { return {std::string_view(buf.data(), header_len)}; }
  std::string_view data() const { return std::string_view(buf.data() + header_len, buf.size() - header_len); }
  [[noreturn]] void fail(std::uint64_t pos, const std::string& what) const {
    throw std::runtime_error(path + ": byte " + std::to_string(pos) + ": " + what);
  }
};

std::string str(std::string_view v) { return std::string(v.data() == nullptr ? "" : v); }

// a chunk's compression ("none", "bz2", "lz4"); false when this build cannot undo it
bool chunk_codec(const std::string& name, BagScan::Codec& out) {
  if (name == "none") return out = BagScan::Codec::kNone, true;
#ifdef DRIFTLESS_HAVE_BZ2
  if (name == "bz2") return out = BagScan::Codec::kBz2, true;
#endif
#ifdef DRIFTLESS_HAVE_LZ4
  if (name == "lz4") return out = BagScan::Codec::kLz4, true;
#endif
  return false;
}

// a chunk's data uncompressed into `plain` (exactly `size` bytes, as its header says); `fail`
// throws naming the chunk
template <class Fail>
std::string_view decompress(BagScan::Codec codec, std::string_view in, std::uint32_t size, std::vector<char>& plain,
                            Fail&& fail) {
  plain.resize(size);
#ifdef DRIFTLESS_HAVE_BZ2
  if (codec == BagScan::Codec::kBz2) {
    unsigned int got = size;
    const int rc = BZ2_bzBuffToBuffDecompress(plain.data(), &got, const_cast<char*>(in.data()),
                                              static_cast<unsigned int>(in.size()), 0, 0);
    if (rc != BZ_OK || got != size) fail("bz2 chunk does not decompress to its " + std::to_string(size) + " bytes (bzip2 code " + std::to_string(rc) + ")");
    return {plain.data(), size};
  }
#endif
#ifdef DRIFTLESS_HAVE_LZ4
  if (codec == BagScan::Codec::kLz4) {
    // roslz4 writes the LZ4 frame format
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) fail("lz4: no decompression context");
    std::size_t out_pos = 0, in_pos = 0, hint = 1;
    while (hint != 0 && in_pos < in.size() && out_pos <= size) {
      std::size_t out_n = size - out_pos, in_n = in.size() - in_pos;
      hint = LZ4F_decompress(ctx, plain.data() + out_pos, &out_n, in.data() + in_pos, &in_n, nullptr);
      if (LZ4F_isError(hint)) break;
      out_pos += out_n, in_pos += in_n;
      if (out_n == 0 && in_n == 0) break;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (hint != 0 || out_pos != size) fail("lz4 chunk does not decompress to its " + std::to_string(size) + " bytes");
    return {plain.data(), size};
  }
#endif
  (void)codec, (void)in;
  fail("chunk compression not supported by this build");
  return {};
}

}  // namespace

BagScan::~BagScan() {
  if (file_ != nullptr) std::fclose(file_);
}

bool BagScan::start(const std::filesystem::path& path, std::string& why) {
  path_ = path.string();
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw std::runtime_error(path_ + ": cannot open");
  // small reads: the index records and the chunk headers checked at open (a chunk is read whole)
  std::setvbuf(file_, nullptr, _IOFBF, 4096);
  char magic[kMagic.size()];
  if (std::fread(magic, 1, kMagic.size(), file_) != kMagic.size() || std::string_view(magic, kMagic.size()) != kMagic) {
    why = "not a bag of format 2.0";
    return false;
  }
  RecordReader rr{file_, path_, buf_};
  if (!rr.read_next(kMagic.size(), false) || rr.fields().op() != kOpBagHeader) {
    why = "no bag header record";
    return false;
  }
  index_pos_ = rr.fields().num<std::uint64_t>("index_pos", path_);
  conn_count_ = rr.fields().num<std::uint32_t>("conn_count", path_);
  chunk_count_ = rr.fields().num<std::uint32_t>("chunk_count", path_);
  if (index_pos_ == 0 || conn_count_ == 0) {
    why = "no index (an unfinished bag)";
    return false;
  }
  return true;
}

// the index's connection records (the file positioned at the index), in id order
std::vector<BagConnection> BagScan::read_connections() {
  RecordReader rr{file_, path_, buf_};
  std::vector<BagConnection> out;
  for (std::uint32_t k = 0; k < conn_count_; ++k) {
    if (!(k == 0 ? rr.read_at(index_pos_, true) : rr.read_next(0, true)) || rr.fields().op() != kOpConnection) {
      rr.fail(index_pos_, "expected " + std::to_string(conn_count_) + " connection records in the index");
    }
    out.push_back({rr.fields().num<std::uint32_t>("conn", path_), str(rr.fields().get("topic")),
                   str(Fields{rr.data()}.get("type"))});
  }
  return out;
}

std::optional<std::vector<BagConnection>> BagScan::connections(const std::filesystem::path& path, std::string& why) {
  BagScan s;
  if (!s.start(path, why)) return std::nullopt;
  auto out = s.read_connections();
  std::sort(out.begin(), out.end(), [](const BagConnection& x, const BagConnection& y) { return x.id < y.id; });
  return out;
}

std::unique_ptr<BagScan> BagScan::open(const std::filesystem::path& path, const std::string& topic, std::string& why) {
  std::unique_ptr<BagScan> s(new BagScan());
  if (!s->start(path, why)) return nullptr;
  // the index: connection records, then chunk info records
  std::vector<const BagConnection*> ours;
  const auto conns = s->read_connections();
  for (const auto& c : conns) {
    if (c.topic == topic) ours.push_back(&c);
  }
  if (ours.size() != 1) {
    why = ours.empty() ? "no connection on " + topic : "the topic on several connections";
    return nullptr;
  }
  if (ours[0]->type != "sensor_msgs/Imu") {
    why = topic + " carries " + ours[0]->type;
    return nullptr;
  }
  s->conn_ = ours[0]->id;
  RecordReader rr{s->file_, s->path_, s->buf_};
  const std::uint64_t index_pos = s->index_pos_;
  const std::uint32_t chunk_count = s->chunk_count_;
  for (std::uint32_t k = 0; k < chunk_count; ++k) {
    if (!rr.read_next(0, true) || rr.fields().op() != kOpChunkInfo) {
      rr.fail(index_pos, "expected " + std::to_string(chunk_count) + " chunk info records in the index");
    }
    Chunk c;
    c.pos = rr.fields().num<std::uint64_t>("chunk_pos", s->path_);
    c.start_ns = static_cast<std::uint64_t>(ns_of_time(rr.fields().num<std::uint64_t>("start_time", s->path_)));
    c.end_ns = static_cast<std::uint64_t>(ns_of_time(rr.fields().num<std::uint64_t>("end_time", s->path_)));
    const std::string_view d = rr.data();
    for (std::size_t p = 0; p + 8 <= d.size(); p += 8) {
      if (load<std::uint32_t>(d.data() + p) == s->conn_) c.ours = load<std::uint32_t>(d.data() + p + 4);
    }
    s->count_ += c.ours;
    if (c.ours > 0) s->chunks_.push_back(c);
  }
  std::sort(s->chunks_.begin(), s->chunks_.end(), [](const Chunk& a, const Chunk& b) { return a.pos < b.pos; });
  std::uint64_t group = 0, group_end_ns = 0;
  for (std::size_t k = 0; k < s->chunks_.size(); ++k) {
    const Chunk& c = s->chunks_[k];
    group = k > 0 && c.start_ns < group_end_ns ? group + c.ours : c.ours;
    group_end_ns = k > 0 ? std::max(group_end_ns, c.end_ns) : c.end_ns;
    if (group > kMaxGroupMessages) {
      why = "chunks overlap in time over more than " + std::to_string(kMaxGroupMessages) + " messages";
      return nullptr;
    }
    rr.read_at(s->chunks_[k].pos, false);
    if (rr.fields().op() != kOpChunk) rr.fail(s->chunks_[k].pos, "expected a chunk record");
    const std::string comp = str(rr.fields().get("compression"));
    if (!chunk_codec(comp, s->chunks_[k].codec)) {
      why = "compressed chunks (" + comp + (comp == "bz2" || comp == "lz4" ? ": this build has no lib" + comp + ")" : ")");
      return nullptr;
    }
    s->chunks_[k].plain_size = s->chunks_[k].codec == Codec::kNone ? 0 : rr.fields().num<std::uint32_t>("size", s->path_);
  }
  return s;
}

// the next chunks that overlap in time (usually one): their messages on our connection, in file
// order, stably sorted by receive time — rosbag::View's order (its index is a multiset by time,
// filled chunk by chunk in file order); the groups follow each other in time
void BagScan::load_group() {
  pending_.clear();
  pending_pos_ = 0;
  std::uint64_t end_ns = chunks_[next_chunk_].end_ns;
  load_chunk(chunks_[next_chunk_++]);
  while (next_chunk_ < chunks_.size() && chunks_[next_chunk_].start_ns < end_ns) {
    end_ns = std::max(end_ns, chunks_[next_chunk_].end_ns);
    load_chunk(chunks_[next_chunk_++]);
  }
  const auto by_time = [](const BagImu& a, const BagImu& b) { return a.receive_ns < b.receive_ns; };
  if (!std::is_sorted(pending_.begin(), pending_.end(), by_time)) std::stable_sort(pending_.begin(), pending_.end(), by_time);
}

// one chunk's messages on our connection, appended in file order
void BagScan::load_chunk(const Chunk& c) {
  RecordReader rr{file_, path_, buf_};
  rr.read_at(c.pos, true);
  const std::uint64_t base = c.pos + 8 + rr.header_len;
  std::string_view d = rr.data();
  if (c.codec != Codec::kNone) {
    d = decompress(c.codec, d, c.plain_size, plain_, [&](const std::string& what) { rr.fail(c.pos, what); });
  }
  for (std::size_t p = 0; p < d.size();) {
    // a compressed chunk's records are located by their offset in the chunk's uncompressed data
    auto bad = [&](const std::string& what) {
      if (c.codec == Codec::kNone) rr.fail(base + p, what);
      rr.fail(c.pos, "uncompressed offset " + std::to_string(p) + ": " + what);
    };
    if (d.size() - p < 8) bad("truncated record in a chunk");
    const auto hl = load<std::uint32_t>(d.data() + p);
    if (hl > d.size() - p - 8) bad("truncated record header in a chunk");
    std::uint32_t conn = 0;
    std::uint64_t time = 0;
    const bool message = message_fields(d.substr(p + 4, hl), conn, time);
    const auto dl = load<std::uint32_t>(d.data() + p + 4 + hl);
    if (dl > d.size() - p - 8 - hl) bad("truncated record data in a chunk");
    const std::string_view m = d.substr(p + 8 + hl, dl);
    if (message && conn == conn_) {
      // std_msgs/Header: seq, stamp (sec, nsec), frame_id (length, bytes)
      if (m.size() < 16) bad("not a sensor_msgs/Imu message (" + std::to_string(m.size()) + " bytes)");
      const auto frame_len = load<std::uint32_t>(m.data() + 12);
      if (frame_len > m.size() - 16 || m.size() - 16 - frame_len < kImuBodyBytes) {
        bad("not a sensor_msgs/Imu message (" + std::to_string(m.size()) + " bytes)");
      }
      BagImu x;
      x.receive_ns = ns_of_time(time);
      x.stamp_ns = static_cast<std::int64_t>(load<std::uint32_t>(m.data() + 4)) * 1'000'000'000 +
                   static_cast<std::int64_t>(load<std::uint32_t>(m.data() + 8));
      const char* body = m.data() + 16 + frame_len;
      for (int k = 0; k < 3; ++k) {
        x.w[k] = load<double>(body + kRateOffset + 8 * k);
        x.a[k] = load<double>(body + kAccelOffset + 8 * k);
      }
      pending_.push_back(x);
    }
    p += 8 + hl + dl;
  }
}

const BagImu* BagScan::peek() {
  while (pending_pos_ == pending_.size()) {
    if (next_chunk_ == chunks_.size()) return nullptr;
    load_group();
  }
  return &pending_[pending_pos_];
}

std::size_t BagScan::take(std::size_t max, const BagImu*& first) {
  first = peek();
  if (first == nullptr) return 0;
  const std::size_t n = std::min(max, pending_.size() - pending_pos_);
  pending_pos_ += n;
  return n;
}

}  // namespace driftless::importers
