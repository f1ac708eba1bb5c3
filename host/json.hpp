// A minimal JSON writer for reports (--json, --stats). Why our own: we only emit, never
// parse, and a small streaming writer is simpler than a dependency.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tc {

class JsonWriter {
 public:
  JsonWriter& begin_object() { value_prefix(); out_ += '{'; first_.push_back(true); return *this; }
  JsonWriter& end_object() { out_ += '}'; first_.pop_back(); return *this; }
  JsonWriter& begin_array() { value_prefix(); out_ += '['; first_.push_back(true); return *this; }
  JsonWriter& end_array() { out_ += ']'; first_.pop_back(); return *this; }
  JsonWriter& key(std::string_view k) {
    separator();
    append_string(k);
    out_ += ':';
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(std::string_view s) { value_prefix(); append_string(s); return *this; }
  JsonWriter& value(const char* s) { return value(std::string_view(s)); }
  JsonWriter& value(const std::string& s) { return value(std::string_view(s)); }
  JsonWriter& value(bool b) { value_prefix(); out_ += b ? "true" : "false"; return *this; }
  JsonWriter& value(int v) { return value(static_cast<int64_t>(v)); }
  JsonWriter& value(int64_t v) { value_prefix(); out_ += std::to_string(v); return *this; }
  JsonWriter& value(uint64_t v) { value_prefix(); out_ += std::to_string(v); return *this; }
  JsonWriter& value(double v);  // non-finite -> null
  JsonWriter& null() { value_prefix(); out_ += "null"; return *this; }
  template <class T>
  JsonWriter& field(std::string_view k, const T& v) { key(k); return value(v); }
  template <class T>
  JsonWriter& array(std::string_view k, const std::vector<T>& v) {
    key(k);
    begin_array();
    for (const auto& x : v) value(x);
    return end_array();
  }
  const std::string& str() const { return out_; }

 private:
  void separator() {
    if (!first_.empty()) {
      if (!first_.back()) out_ += ',';
      first_.back() = false;
    }
  }
  void value_prefix() {
    if (after_key_) { after_key_ = false; return; }
    separator();
  }
  void append_string(std::string_view s);
  std::string out_;
  std::vector<bool> first_;
  bool after_key_ = false;
};

}  // namespace tc
