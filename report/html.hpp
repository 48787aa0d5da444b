// HTML pieces for the self-contained reports (report.html): escaping and inline images.
#pragma once

#include <string>
#include <string_view>

namespace driftless::report {

/// Text safe inside HTML elements and double-quoted attributes (& < > " ').
std::string html_escape(std::string_view s);
/// Standard base64 (RFC 4648, with padding) of bytes.
std::string base64(std::string_view bytes);
/// An <img> with the PNG bytes inline (data URI), alt text escaped.
std::string inline_png(std::string_view png_bytes, std::string_view alt);

}  // namespace driftless::report
