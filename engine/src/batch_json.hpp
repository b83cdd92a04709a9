// Streaming JSON reading for batch files: a SAX handler that builds the DOM of one element of the top-level "shapes"
// and "pairs" arrays at a time and hands each to a consumer as soon as it is complete, so memory stays proportional
// to the results, never to a DOM of the whole file (100 MB of `{},` took 3.6 GB as one DOM: issue #16, item 5).
// Limits (each a clear error naming the JSON pointer): nesting depth kMaxJsonDepth; per element an estimated DOM
// size of at most 16 bytes per byte of the file plus 64 KiB; the top level must be an object; its keys must be
// known; "shapes"/"pairs" must be arrays and the other top-level values scalars. Duplicate keys are errors too
// (json::parse keeps the last silently).
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace batchcol::detail {

/// Deepest nesting a batch file may have (a valid one needs 6: root, pairs, pair, pose, rotation, row).
constexpr std::size_t kMaxJsonDepth = 16;

std::string pointer_token(const std::string& key);

/// What the handler hands out: an element of a top-level array, and the end of that array.
struct JsonConsumer {
  std::function<void(const std::string& array, std::size_t index, const nlohmann::json& element)> element;
  std::function<void(const std::string& array)> array_end;
};

class StreamingDom final : public nlohmann::json_sax<nlohmann::json> {
 public:
  using json = nlohmann::json;
  /// `streamed`: the top-level keys whose arrays are streamed; `allowed`: every top-level key.
  StreamingDom(const std::string& text, json& root, std::vector<std::string> streamed, std::vector<std::string> allowed,
               JsonConsumer consumer);

  bool null() override { return add(json(nullptr)); }
  bool boolean(bool v) override { return add(json(v)); }
  bool number_integer(number_integer_t v) override { return add(json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return add(json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return add(json(v)); }
  bool string(string_t& v) override;
  bool binary(binary_t&) override { return false; }  // JSON text never holds binary values
  bool start_object(std::size_t) override { return open(json::object()); }
  bool start_array(std::size_t) override { return open(json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override;
  bool parse_error(std::size_t position, const std::string& last_token, const json::exception& ex) override;

  std::optional<std::size_t> error_index;  // index into the text, for syntax errors only
  std::string error_pointer;
  std::string error_message;

 private:
  struct Frame {
    json* value;
    std::string key;           // key of the member being read (objects only)
    std::size_t consumed = 0;  // elements already handed to the consumer (streamed arrays only)
  };

  json* insert(json v);
  bool add(json v);
  bool open(json v);
  bool close();
  bool fail(std::string pointer, std::string message);
  bool charge(std::size_t bytes);
  void hand_out_if_complete();
  bool streamed_array(std::size_t depth) const;
  std::string child_token(const Frame& frame, bool next) const;
  std::string container_pointer() const;
  std::string value_pointer() const;

  const std::string& text_;
  json& root_;
  std::vector<std::string> streamed_, allowed_;
  JsonConsumer consumer_;
  std::vector<Frame> stack_;
  std::size_t element_bytes_ = 0;  // estimated DOM bytes of the element being built
  std::size_t element_budget_;
};

/// 1-based line and column of the character at `index` (index == size means the end of the text).
std::pair<std::size_t, std::size_t> line_and_column(const std::string& text, std::size_t index);

}  // namespace batchcol::detail
