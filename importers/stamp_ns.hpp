// Stamps as integers (docs/import.md, time): an epoch stamp in ns (1.4e18 for 2014) held as double
// seconds keeps only 2.4e-7 s; the readers parse it into whole ns, subtract the epoch (whole
// seconds) in integers, and only then convert the small difference to seconds. C++17 (the bag
// reader includes it).
#pragma once

#include <cstdint>

namespace driftless::importers {

/// A plain decimal stamp [b, e) ("1403636579758555392", "1403636579.758555") in a unit of
/// `ns_per_unit` ns (s: 1e9, ms: 1e6, us: 1e3, ns: 1) as whole ns, digits below 1 ns rounded.
/// False when the text is not a plain decimal (an exponent, nan, blanks) or does not fit 64 bits. A date
/// and time (parse_datetime_ns) is read too when the unit is s.
bool parse_stamp_ns(const char* b, const char* e, std::int64_t ns_per_unit, std::int64_t& ns);
/// A date and time [b, e) as phone apps and Python loggers write it, "2024-05-01 12:00:00.125" (or with
/// 'T', a trailing 'Z', or an offset "+02:00"), as whole ns since 1970-01-01 UTC (no offset: read as UTC).
/// Digits below 1 ns dropped. False when the text is not of that form or not a valid date.
bool parse_datetime_ns(const char* b, const char* e, std::int64_t& ns);
/// The whole seconds at or below a stamp in ns: the epoch the readers count time from.
std::int64_t epoch_s_of(std::int64_t ns);
/// Seconds from `epoch_s` to the stamp, the difference formed in integers.
double seconds_since(std::int64_t ns, std::int64_t epoch_s);
/// ns per unit of a time unit's factor to s (1, 1e-3, 1e-6, 1e-9 -> 1e9, 1e6, 1e3, 1); 0 otherwise.
std::int64_t ns_per_unit_of(double unit_to_s);

}  // namespace driftless::importers
