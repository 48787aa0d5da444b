// Numbers as text, exactly: the one formatter for every number the program writes for a machine
// to read back (YAML files, log metadata, JSON, config), and the one strict number parser.
// Standard library only.
#pragma once

#include <string>
#include <string_view>

namespace driftless {

/// The shortest decimal text that reads back to exactly `v` (round trip), written like Python's
/// repr and fmt's "{}": fixed notation for decimal exponents -4..15 ("600", "0.0001", "0.005"),
/// scientific otherwise ("1e-05", "1e+16"); "nan", "inf", "-inf" for the non-finite values.
std::string exact_number(double v);

/// Parses all of `text` as a decimal number (an optional leading '+' allowed, no spaces, no
/// trailing characters, locale independent). Returns false on anything else; "inf"/"nan" parse.
bool parse_decimal(std::string_view text, double& out);

}  // namespace driftless
