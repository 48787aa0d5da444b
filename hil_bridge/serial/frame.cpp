#include "hil_bridge/serial/frame.hpp"

#include <cstring>

namespace driftless::hil::serial {

std::uint16_t crc16_ccitt(const std::uint8_t* data, std::size_t n, std::uint16_t crc) {
  for (std::size_t i = 0; i < n; ++i) {
    crc = static_cast<std::uint16_t>(crc ^ (data[i] << 8));
    for (int b = 0; b < 8; ++b) {
      crc = (crc & 0x8000) ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021) : static_cast<std::uint16_t>(crc << 1);
    }
  }
  return crc;
}

namespace {
void put16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}
std::uint16_t get16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
std::uint32_t get32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
// the CRC covers type, length and payload
void finish(std::vector<std::uint8_t>& out, std::size_t start) {
  put16(out, crc16_ccitt(out.data() + start + 2, out.size() - start - 2));
}
}  // namespace

void encode(const SampleFrame& f, std::vector<std::uint8_t>& out) {
  const std::size_t start = out.size();
  for (std::uint8_t b : {kSync0, kSync1, kTypeSample, static_cast<std::uint8_t>(kSamplePayloadBytes)}) out.push_back(b);
  put16(out, f.seq);
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(f.t_us >> (8 * i)));
  out.insert(out.end(), f.sensor1.begin(), f.sensor1.end());
  out.insert(out.end(), f.sensor2.begin(), f.sensor2.end());
  out.push_back(f.config);
  out.push_back(f.end_stops);
  out.push_back(f.status);
  finish(out, start);
}

void encode(const MotorCommand& c, std::vector<std::uint8_t>& out) {
  const std::size_t start = out.size();
  for (std::uint8_t b : {kSync0, kSync1, kTypeMotor, static_cast<std::uint8_t>(kMotorPayloadBytes), c.seq,
                         static_cast<std::uint8_t>(c.target1), static_cast<std::uint8_t>(c.target2)}) {
    out.push_back(b);
  }
  finish(out, start);
}

void Decoder::feed(const std::uint8_t* data, std::size_t n) {
  // drop what was consumed before growing the buffer
  if (pos_ > 0 && pos_ >= buf_.size() / 2) {
    buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(pos_));
    pos_ = 0;
  }
  buf_.insert(buf_.end(), data, data + n);
}

Decoder::Result Decoder::next(SampleFrame* sample, MotorCommand* motor) {
  for (;;) {
    // find the sync pattern
    while (pos_ + 1 < buf_.size() && !(buf_[pos_] == kSync0 && buf_[pos_ + 1] == kSync1)) {
      ++pos_;
      ++skipped_;
    }
    if (pos_ + kHeaderBytes > buf_.size()) return Result::kNone;
    const std::uint8_t* h = buf_.data() + pos_;
    const std::size_t len = h[3];
    const bool known = (h[2] == kTypeSample && len == kSamplePayloadBytes) ||
                       (h[2] == kTypeMotor && len == kMotorPayloadBytes);
    if (!known) {
      // not a frame start after all (or a damaged header): skip the sync byte and search on
      ++corrupt_;
      ++pos_;
      ++skipped_;
      return Result::kCorrupt;
    }
    const std::size_t total = kHeaderBytes + len + kCrcBytes;
    if (pos_ + total > buf_.size()) return Result::kNone;
    const std::uint16_t crc = crc16_ccitt(h + 2, 2 + len);
    if (crc != get16(h + kHeaderBytes + len)) {
      ++corrupt_;
      ++pos_;  // resynchronise from the next byte: the real next frame may start inside this one
      ++skipped_;
      return Result::kCorrupt;
    }
    const std::uint8_t* p = h + kHeaderBytes;
    pos_ += total;
    if (h[2] == kTypeSample) {
      if (!sample) continue;
      sample->seq = get16(p);
      sample->t_us = get32(p + 2);
      std::memcpy(sample->sensor1.data(), p + 6, 14);
      std::memcpy(sample->sensor2.data(), p + 20, 14);
      sample->config = p[34];
      sample->end_stops = p[35];
      sample->status = p[36];
      return Result::kSample;
    }
    if (!motor) continue;
    motor->seq = p[0];
    motor->target1 = static_cast<std::int8_t>(p[1]);
    motor->target2 = static_cast<std::int8_t>(p[2]);
    return Result::kMotor;
  }
}

}  // namespace driftless::hil::serial
