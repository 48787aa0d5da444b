// The serial link's binary frames (byte by byte in docs/hil.md). Microcontroller -> host: one
// sample frame per sample with both sensors' raw registers, the end-stop switches and a CRC.
// Host -> microcontroller: motor commands. Little-endian fields, except the sensor registers,
// which are passed through as the MPU-6050 gives them (big-endian int16).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hil_bridge/i2c/mpu6050_regs.hpp"

namespace driftless::hil::serial {

inline constexpr std::uint8_t kSync0 = 0xA5;
inline constexpr std::uint8_t kSync1 = 0x5A;
inline constexpr std::uint8_t kTypeSample = 0x01;
inline constexpr std::uint8_t kTypeMotor = 0x10;
inline constexpr std::size_t kHeaderBytes = 4;  // sync0 sync1 type length
inline constexpr std::size_t kCrcBytes = 2;
inline constexpr std::size_t kSamplePayloadBytes = 37;
inline constexpr std::size_t kSampleFrameBytes = kHeaderBytes + kSamplePayloadBytes + kCrcBytes;  // 43
inline constexpr std::size_t kMotorPayloadBytes = 3;
inline constexpr std::size_t kMotorFrameBytes = kHeaderBytes + kMotorPayloadBytes + kCrcBytes;  // 9
inline constexpr std::size_t kMaxPayloadBytes = 64;

// end-stop byte
inline constexpr std::uint8_t kStop1Minus = 0x01, kStop1Plus = 0x02, kStop2Minus = 0x04, kStop2Plus = 0x08;
inline constexpr std::uint8_t kMotor1Driving = 0x10, kMotor2Driving = 0x20;
// status byte
inline constexpr std::uint8_t kStatusSensor1Failed = 0x01, kStatusSensor2Failed = 0x02;
inline constexpr std::uint8_t kStatusMcuOverflow = 0x04;

/// CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection, no final xor.
std::uint16_t crc16_ccitt(const std::uint8_t* data, std::size_t n, std::uint16_t crc = 0xFFFF);

/// The content of one sample frame.
struct SampleFrame {
  std::uint16_t seq = 0;           // increments by one per sample, wraps at 65536
  std::uint32_t t_us = 0;          // microcontroller time of the sample, us, wraps at 2^32
  std::array<std::uint8_t, 14> sensor1{};  // registers 0x3B..0x48 of sensor 1
  std::array<std::uint8_t, 14> sensor2{};  // of sensor 2
  std::uint8_t config = 0;         // bits 0-1 FS_SEL, bits 2-3 AFS_SEL
  std::uint8_t end_stops = 0;      // kStop* / kMotor* bits
  std::uint8_t status = 0;         // kStatus* bits
};

/// A motor command: each platform to its -1 / +1 end stop, 0 = stop where it is.
struct MotorCommand {
  std::uint8_t seq = 0;
  std::int8_t target1 = 0;
  std::int8_t target2 = 0;
};

/// Appends the encoded frame to `out`.
void encode(const SampleFrame& f, std::vector<std::uint8_t>& out);
void encode(const MotorCommand& c, std::vector<std::uint8_t>& out);

/// Streaming decoder: feed bytes as they come, take frames out. Bad CRCs and stray bytes are
/// counted; the decoder resynchronises on the next sync pattern.
class Decoder {
 public:
  enum class Result { kNone, kSample, kMotor, kCorrupt };
  void feed(const std::uint8_t* data, std::size_t n);
  /// Next complete item: a sample frame, a motor command, or one corrupt frame (kCorrupt).
  Result next(SampleFrame* sample, MotorCommand* motor);
  std::uint64_t corrupt_frames() const { return corrupt_; }
  std::uint64_t skipped_bytes() const { return skipped_; }
  void reset() {
    buf_.clear();
    pos_ = 0;
  }

 private:
  std::vector<std::uint8_t> buf_;
  std::size_t pos_ = 0;
  std::uint64_t corrupt_ = 0;
  std::uint64_t skipped_ = 0;
};

}  // namespace driftless::hil::serial
