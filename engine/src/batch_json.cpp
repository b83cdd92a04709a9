#include "batch_json.hpp"

#include "printable.hpp"

#include <algorithm>
#include <utility>

namespace batchcol::detail {

std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : printable(key, 64)) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

StreamingDom::StreamingDom(const std::string& text, json& root, std::vector<std::string> streamed,
                           std::vector<std::string> allowed, JsonConsumer consumer)
    : text_(text), root_(root), streamed_(std::move(streamed)), allowed_(std::move(allowed)),
      consumer_(std::move(consumer)), element_budget_(16 * text.size() + 65536) {}

bool StreamingDom::string(string_t& v) {
  // A short string lives inside the json value (small-string optimisation); a long one also holds its characters.
  return charge(v.size() > 15 ? 16 + v.size() : 16) && add(json(std::move(v)));
}

bool StreamingDom::key(string_t& k) {
  Frame& frame = stack_.back();
  if (stack_.size() == 1 && std::find(allowed_.begin(), allowed_.end(), k) == allowed_.end()) {
    std::string list;
    for (const std::string& name : allowed_) list += (list.empty() ? "" : ", ") + name;
    return fail("/" + pointer_token(k), "unknown key '" + printable(k, 64) + "' (allowed here: " + list + ")");
  }
  if (frame.value->contains(k)) return fail(container_pointer() + "/" + pointer_token(k), "duplicate key");
  // A map node: the key string, the value and the tree links.
  if (!charge(64 + k.size())) return false;
  frame.key = std::move(k);
  return true;
}

bool StreamingDom::parse_error(std::size_t position, const std::string& last_token, const json::exception& ex) {
  // `position` counts the characters read, i.e. it is just past the offending token; point at the token's start.
  error_index = position > 0 ? position - 1 : 0;
  if (!last_token.empty() && position >= last_token.size() &&
      text_.compare(position - last_token.size(), last_token.size(), last_token) == 0) {
    error_index = position - last_token.size();
  }
  // A number overflow is a complete value, so the pointer of that value is exact; other errors name the container.
  error_pointer = ex.id == 406 ? value_pointer() : container_pointer();
  std::string what = ex.what();
  const auto bracket = what.find("] ");
  if (bracket != std::string::npos) what.erase(0, bracket + 2);
  if (what.rfind("parse error", 0) == 0) {  // drop nlohmann's own "parse error at line L, column C: "
    const auto colon = what.find(": ");
    if (colon != std::string::npos) what.erase(0, colon + 2);
  }
  // nlohmann quotes the offending token (e.g. the rest of an unterminated string): keep the message one short line.
  error_message = "invalid JSON: " + printable(what, 200);
  return false;
}

bool StreamingDom::fail(std::string pointer, std::string message) {
  error_pointer = std::move(pointer);
  error_message = std::move(message);
  return false;
}

bool StreamingDom::streamed_array(std::size_t depth) const {
  return stack_.size() > depth && depth >= 1 && stack_[1].value->is_array() &&
         std::find(streamed_.begin(), streamed_.end(), stack_[0].key) != streamed_.end();
}

bool StreamingDom::charge(std::size_t bytes) {
  if (!streamed_array(1)) return true;  // outside the streamed arrays only top-level scalars are allowed
  element_bytes_ += bytes;
  if (element_bytes_ <= element_budget_) return true;
  return fail("/" + stack_[0].key + "/" + std::to_string(stack_[1].consumed),
              "this element would take more than " + std::to_string(element_budget_) +
                  " bytes of memory (16 per byte of the file, plus 64 KiB)");
}

StreamingDom::json* StreamingDom::insert(json v) {
  if (stack_.empty()) {
    root_ = std::move(v);
    return &root_;
  }
  Frame& parent = stack_.back();
  if (parent.value->is_array()) {
    parent.value->push_back(std::move(v));
    return &parent.value->back();
  }
  json& slot = (*parent.value)[parent.key];
  slot = std::move(v);
  return &slot;
}

bool StreamingDom::add(json v) {
  if (stack_.empty()) return fail("top level", std::string("the top level must be an object, got ") + v.type_name());
  if (!charge(16)) return false;
  insert(std::move(v));
  hand_out_if_complete();
  return true;
}

bool StreamingDom::open(json v) {
  if (stack_.empty() && !v.is_object()) {
    return fail("top level", std::string("the top level must be an object, got ") + v.type_name());
  }
  if (stack_.size() >= kMaxJsonDepth) {
    return fail(container_pointer(), "nesting deeper than " + std::to_string(kMaxJsonDepth) +
                                         " levels (a batch file needs at most 6)");
  }
  if (stack_.size() == 1) {  // a top-level member
    const bool streamed = std::find(streamed_.begin(), streamed_.end(), stack_[0].key) != streamed_.end();
    if (streamed && !v.is_array()) return fail("/" + stack_[0].key, "expected an array, got an object");
    if (!streamed) return fail(value_pointer(), std::string("expected a string or a number, got an ") + v.type_name());
  }
  // An array: its vector and allocation; an object: its map and allocation.
  if (!charge(v.is_array() ? 56 : 80)) return false;
  stack_.push_back({insert(std::move(v)), {}, 0});
  return true;
}

bool StreamingDom::close() {
  stack_.pop_back();
  if (stack_.size() == 1 && std::find(streamed_.begin(), streamed_.end(), stack_[0].key) != streamed_.end()) {
    consumer_.array_end(stack_[0].key);
  }
  hand_out_if_complete();
  return true;
}

void StreamingDom::hand_out_if_complete() {
  if (stack_.size() != 2 || !streamed_array(1)) return;
  Frame& array = stack_[1];
  consumer_.element(stack_[0].key, array.consumed, array.value->back());
  array.value->erase(array.value->size() - 1);
  ++array.consumed;
  element_bytes_ = 0;
}

std::string StreamingDom::child_token(const Frame& frame, bool next) const {
  if (!frame.value->is_array()) return pointer_token(frame.key);
  const std::size_t n = frame.value->size() + frame.consumed;
  return std::to_string(next ? n : n - 1);
}

std::string StreamingDom::container_pointer() const {
  std::string out;
  for (std::size_t i = 1; i < stack_.size(); ++i) out += "/" + child_token(stack_[i - 1], false);
  return out;
}

std::string StreamingDom::value_pointer() const {
  return stack_.empty() ? std::string() : container_pointer() + "/" + child_token(stack_.back(), true);
}

std::pair<std::size_t, std::size_t> line_and_column(const std::string& text, std::size_t index) {
  index = std::min(index, text.size());
  std::size_t line = 1, line_start = 0;
  for (std::size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return {line, index - line_start + 1};
}

}  // namespace batchcol::detail
