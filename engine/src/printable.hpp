// Untrusted text (file names, JSON keys and strings, flag values) inside an error message: the message must stay one
// bounded line (issue #16, item 14), whatever the text holds.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace batchcol::detail {

/// `text` with control bytes (newline, NUL, escape, ...) written as \n, \t, \r or \xNN, cut after `max` bytes with
/// "...(N bytes)" appended. Bytes >= 0x80 are kept: UTF-8 names stay readable.
inline std::string printable(std::string_view text, std::size_t max = 80) {
  std::string out;
  const std::size_t n = text.size() > max ? max : text.size();
  out.reserve(n + 24);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c == '\r') out += "\\r";
    else if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (text.size() > max) out += "...(" + std::to_string(text.size()) + " bytes)";
  return out;
}

}  // namespace batchcol::detail
