// Fixed-point decimal text of a double and back, fast: the log writer and the estimate outputs
// write tens of millions of numbers, and the log reader parses them. The writer gives the same
// bytes as std::to_chars(..., std::chars_format::fixed, decimals), so logs stay byte-identical to
// those of earlier versions; the parser gives the same double as std::from_chars.
// Standard library only.
#pragma once

namespace driftless::io {

/// Longest text write_fixed() produces for |v| < 1e17 (sign, 17 digits, point, 17 decimals).
inline constexpr int kFixedMaxChars = 40;

/// Writes `v` with `decimals` (0..17) digits after the point at `out` and returns the end.
/// Finite values whose scaled magnitude stays below 2^52 take an integer path; ties, huge values,
/// inf and nan fall back to std::to_chars (which then decides the bytes). `out` must hold
/// kFixedMaxChars chars, or 330 for any double.
char* write_fixed(char* out, double v, int decimals);

/// Parses a decimal number starting at `first` (an optional sign, digits, an optional point and
/// digits, or anything std::from_chars reads: exponents, inf, nan) and returns the end of what it
/// read, or nullptr when there is no number at `first`. Plain fixed-point text of at most 15
/// significant digits takes an exact integer path (n / 10^d is correctly rounded, as from_chars);
/// everything else goes to std::from_chars. Spaces are not skipped.
const char* parse_decimal(const char* first, const char* last, double& out);

}  // namespace driftless::io
