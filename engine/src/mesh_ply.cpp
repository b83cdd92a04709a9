// PLY checks before assimp reads a file. Assimp 5.2.5's PLY reader trusts the header (found by tools/fuzz and an
// adversarial probe, issue #16): it loops forever on a header without end_header, overflows a heap buffer on an
// element declared twice, segfaults on a 1 MiB .ply whose first byte is NUL, reserves whatever count an element
// declares (1e9 vertices took 11.7 GB; 2e9 faces ended in std::bad_alloc), and reads an ASCII file declaring more
// vertices than it holds by taking the face lines as vertices (a wrong mesh, accepted). So the header grammar is
// checked, then the body is walked and must hold exactly the declared elements:
// - binary: each element's count times its smallest row must fit in the bytes left before anything else is read,
//   each list length must fit too, and the data must end exactly at the end of the file;
// - ASCII: assimp reads one element per line, so every element is one line with exactly the values its properties
//   declare (a list: its length, then that many values), every value a number; only blank lines may follow.
// Every element must have at least one property, so each costs at least one byte of the file: a file passing these
// checks makes assimp allocate in proportion to its size.
#include "mesh_checks.hpp"

#include "batchcol/errors.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace batchcol::detail {
namespace {

struct Property {
  int bytes = 0;        // size of the value (scalar) or of each item (list)
  int count_bytes = 0;  // 0 for a scalar, else the size of the list's length
};
struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};
enum class Format { ascii, little, big };
struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  std::size_t body = 0;         // offset of the first byte after the end_header line
  std::size_t body_line = 0;    // 1-based line number of the body's first line
};

int type_bytes(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}
bool is_integer_type(const std::string& t) { return type_bytes(t) > 0 && t.find("float") == std::string::npos && t != "double"; }

// Header grammar: "ply", one "format ascii|binary_little_endian|binary_big_endian 1.0", then "comment"/"obj_info"
// lines, "element NAME COUNT" (unique names) each followed by its "property TYPE NAME" or "property list COUNT_TYPE
// ITEM_TYPE NAME" lines (a list's length type must be an integer type), then "end_header".
Header parse_header(const std::string& text, const std::string& what) {
  const auto fail = [&](std::size_t number, const std::string& problem) {
    throw InputError(what + ": PLY header line " + std::to_string(number) + ": " + problem);
  };
  Header h;
  bool format_seen = false;
  std::size_t at = 0;
  for (std::size_t number = 1; at < text.size(); ++number) {
    std::size_t end = text.find('\n', at);
    const std::size_t next = end == std::string::npos ? text.size() : end + 1;
    std::string line = text.substr(at, (end == std::string::npos ? text.size() : end) - at);
    at = next;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      if (line != "ply") fail(1, "expected 'ply' alone on the first line");
      continue;
    }
    const bool text_only = std::none_of(line.begin(), line.end(), [](unsigned char c) {
      return (c < 32 && c != '\t') || c >= 127;
    });
    if (!text_only && line.rfind("comment", 0) != 0 && line.rfind("obj_info", 0) != 0) fail(number, "not a text line");
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (!format_seen) fail(number, "end_header before the format line");
      for (const Element& e : h.elements)
        if (e.properties.empty()) fail(number, "element '" + e.name.substr(0, 40) + "' has no properties");
      h.body = at;
      h.body_line = number + 1;
      return h;
    }
    if (w[0] == "format") {
      if (format_seen || w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian")) {
        fail(number, "expected one 'format ascii|binary_little_endian|binary_big_endian 1.0' line");
      }
      h.format = w[1] == "ascii" ? Format::ascii : w[1] == "binary_little_endian" ? Format::little : Format::big;
      format_seen = true;
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].find_first_not_of("0123456789") != std::string::npos || w[2].size() > 18)
        fail(number, "expected 'element NAME COUNT'");
      for (const Element& e : h.elements)
        if (e.name == w[1]) fail(number, "element '" + w[1].substr(0, 40) + "' declared twice");
      h.elements.push_back({w[1], std::stoull(w[2]), {}});
    } else if (w[0] == "property") {
      const bool scalar = w.size() == 3 && type_bytes(w[1]) > 0;
      const bool list = w.size() == 5 && w[1] == "list" && is_integer_type(w[2]) && type_bytes(w[3]) > 0;
      if (h.elements.empty() || !(scalar || list))
        fail(number, "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME' after an element");
      h.elements.back().properties.push_back(scalar ? Property{type_bytes(w[1]), 0}
                                                    : Property{type_bytes(w[3]), type_bytes(w[2])});
    } else {
      fail(number, "unknown keyword '" + w[0].substr(0, 40) + "'");
    }
  }
  throw InputError(what + ": PLY header has no end_header line");
}

std::string declared(const Element& e) {
  return std::to_string(e.count) + " '" + e.name.substr(0, 40) + "' elements";
}

void check_binary_body(const std::string& text, const Header& h, const std::string& what) {
  std::uint64_t at = h.body;
  const std::uint64_t size = text.size();
  const auto read_count = [&](std::uint64_t offset, int bytes, bool big) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) {
      const int k = big ? i : bytes - 1 - i;
      v = (v << 8) | static_cast<unsigned char>(text[offset + static_cast<std::uint64_t>(k)]);
    }
    return v;
  };
  for (const Element& e : h.elements) {
    std::uint64_t min_row = 0;
    bool fixed = true;
    for (const Property& p : e.properties) {
      min_row += p.count_bytes ? static_cast<std::uint64_t>(p.count_bytes) : static_cast<std::uint64_t>(p.bytes);
      fixed = fixed && p.count_bytes == 0;
    }
    const std::uint64_t left = size - at;
    if (e.count > left / min_row) {
      throw InputError(what + ": binary PLY declares " + declared(e) + " of at least " + std::to_string(min_row) +
                       " bytes each, but only " + std::to_string(left) + " bytes are left in the file");
    }
    if (fixed) {
      at += e.count * min_row;
      continue;
    }
    for (std::uint64_t i = 0; i < e.count; ++i)
      for (const Property& p : e.properties) {
        if (p.count_bytes == 0) {
          if (size - at < static_cast<std::uint64_t>(p.bytes)) at = size + 1;
          else at += static_cast<std::uint64_t>(p.bytes);
        } else if (size - at >= static_cast<std::uint64_t>(p.count_bytes)) {
          // Signed length types: a negative length reads as a huge unsigned value and fails the fit check.
          const std::uint64_t n = read_count(at, p.count_bytes, h.format == Format::big);
          at += static_cast<std::uint64_t>(p.count_bytes);
          if (n > (size - at) / static_cast<std::uint64_t>(p.bytes)) {
            throw InputError(what + ": binary PLY '" + e.name.substr(0, 40) + "' element " + std::to_string(i) +
                             " has a list of " + std::to_string(n) + " items, more than the " +
                             std::to_string(size - at) + " bytes left in the file");
          }
          at += n * static_cast<std::uint64_t>(p.bytes);
        } else {
          at = size + 1;
        }
        if (at > size) {
          throw InputError(what + ": binary PLY ends inside '" + e.name.substr(0, 40) + "' element " +
                           std::to_string(i) + " (the header declares " + declared(e) + ")");
        }
      }
  }
  if (at != size) {
    throw InputError(what + ": binary PLY has " + std::to_string(size - at) +
                     " bytes after the elements its header declares");
  }
}

bool is_number(const std::string& token, bool integer) {
  errno = 0;
  char* end = nullptr;
  if (integer) std::strtoll(token.c_str(), &end, 10);
  else std::strtod(token.c_str(), &end);
  return !token.empty() && end == token.c_str() + token.size() && errno == 0;
}

void check_ascii_body(const std::string& text, const Header& h, const std::string& what) {
  // Lines of the body: a count first, so that a header lying about its counts is refused before anything is read.
  const std::uint64_t lines = static_cast<std::uint64_t>(std::count(text.begin() + static_cast<std::ptrdiff_t>(h.body),
                                                                    text.end(), '\n')) + 1;
  std::uint64_t total = 0;
  for (const Element& e : h.elements) {
    total += std::min<std::uint64_t>(e.count, lines + 1);  // capped: the sum cannot overflow
    if (total > lines) {
      throw InputError(what + ": ASCII PLY declares " + declared(e) + " (with those before it, " +
                       std::to_string(total) + "+ lines) but the body has only " + std::to_string(lines) + " lines");
    }
  }
  std::size_t at = h.body, number = h.body_line;
  const auto next_line = [&] {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    std::string line = text.substr(at, end - at);
    at = end + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  for (const Element& e : h.elements)
    for (std::uint64_t i = 0; i < e.count; ++i) {
      const std::size_t line_number = number;
      std::istringstream in(next_line());
      const std::vector<std::string> values{std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
      const auto fail = [&](const std::string& problem) {
        throw InputError(what + ": ASCII PLY line " + std::to_string(line_number) + " ('" + e.name.substr(0, 40) +
                         "' element " + std::to_string(i) + " of " + std::to_string(e.count) + "): " + problem);
      };
      std::size_t k = 0;
      for (const Property& p : e.properties) {
        std::uint64_t n = 1;
        if (p.count_bytes) {
          if (k >= values.size() || !is_number(values[k], true) || values[k][0] == '-')
            fail("expected a list length (a non-negative integer)");
          n = std::stoull(values[k++]);
        }
        if (n > values.size() - k) fail("has " + std::to_string(values.size()) + " values, fewer than its properties need");
        for (std::uint64_t j = 0; j < n; ++j, ++k)
          if (!is_number(values[k], false)) fail("value '" + values[k].substr(0, 40) + "' is not a number");
      }
      if (k != values.size()) {
        fail("has " + std::to_string(values.size()) + " values, its properties need " + std::to_string(k));
      }
    }
  while (at < text.size()) {
    const std::size_t line_number = number;
    const std::string line = next_line();
    if (line.find_first_not_of(" \t") != std::string::npos) {
      throw InputError(what + ": ASCII PLY line " + std::to_string(line_number) +
                       " holds data after the elements its header declares");
    }
  }
}

}  // namespace

void check_ply(const std::string& path, std::uint64_t size, const std::string& what, bool ply_extension) {
  std::ifstream in(path, std::ios::binary);
  std::string head(3, '\0');
  in.read(head.data(), 3);
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::transform(head.begin(), head.end(), head.begin(), [](unsigned char c) { return std::tolower(c); });
  // Assimp takes any capitalisation of the magic ("pLy" was a fuzzer find) and chooses its PLY reader by the
  // extension as well: a .ply file must be a PLY file.
  if (head != "ply") {
    if (!ply_extension) return;
    throw InputError(what + ": not a PLY file (a .ply file must start with the line 'ply')");
  }
  in.seekg(0);
  std::string text(size, '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(size))) throw InputError(what + ": read error");
  const Header header = parse_header(text, what);
  if (header.format == Format::ascii) check_ascii_body(text, header, what);
  else check_binary_body(text, header, what);
}

}  // namespace batchcol::detail
