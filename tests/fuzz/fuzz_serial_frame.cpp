// libFuzzer harness: the serial frame decoder of the box's microcontroller link on arbitrary
// bytes, fed in pieces of varying size; it must resynchronise and never read out of bounds.
#include <cstdint>

#include "hil_bridge/serial/frame.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using driftless::hil::serial::Decoder;
  Decoder d;
  std::size_t pos = 0;
  std::size_t items = 0;
  while (pos < size) {
    const std::size_t n = 1 + (data[pos] % 37);  // piece sizes from the input itself
    const std::size_t take = pos + n <= size ? n : size - pos;
    d.feed(data + pos, take);
    pos += take;
    driftless::hil::serial::SampleFrame s;
    driftless::hil::serial::MotorCommand m;
    for (;;) {
      const Decoder::Result r = d.next(&s, &m);
      if (r == Decoder::Result::kNone) break;
      if (++items > 4 * size + 16) __builtin_trap();  // more items than bytes: a decoder that loops
    }
  }
  return 0;
}
