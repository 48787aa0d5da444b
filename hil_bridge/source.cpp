#include "hil_bridge/source.hpp"

namespace driftless::hil {

const char* to_string(ReadStatus s) {
  switch (s) {
    case ReadStatus::kSample: return "sample";
    case ReadStatus::kPending: return "pending";
    case ReadStatus::kFault: return "fault";
    case ReadStatus::kDisconnected: return "disconnected";
    case ReadStatus::kEnd: return "end";
    case ReadStatus::kFailed: return "failed";
  }
  return "?";
}

const char* to_string(EventKind k) {
  switch (k) {
    case EventKind::kBusError: return "bus-error";
    case EventKind::kTimeout: return "timeout";
    case EventKind::kDisconnected: return "disconnected";
    case EventKind::kReconnected: return "reconnected";
    case EventKind::kCorruptFrame: return "corrupt-frame";
    case EventKind::kSequenceGap: return "sequence-gap";
    case EventKind::kFifoOverflow: return "fifo-overflow";
    case EventKind::kSaturation: return "saturation";
    case EventKind::kGap: return "gap";
    case EventKind::kSwitch: return "switch";
    case EventKind::kInfo: return "info";
  }
  return "?";
}

}  // namespace driftless::hil
