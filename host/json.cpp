#include "json.hpp"

#include <cstdio>

#include "io/io_util.hpp"

namespace tc {

JsonWriter& JsonWriter::value(double v) {
  value_prefix();
  if (!std::isfinite(v)) {
    out_ += "null";
  } else {
    io::append_double(out_, v);
  }
  return *this;
}

void JsonWriter::append_string(std::string_view s) {
  out_ += '"';
  for (char c : s) {
    switch (c) {
      case '"': out_ += "\\\""; break;
      case '\\': out_ += "\\\\"; break;
      case '\n': out_ += "\\n"; break;
      case '\t': out_ += "\\t"; break;
      case '\r': out_ += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out_ += buf;
        } else {
          out_ += c;
        }
    }
  }
  out_ += '"';
}

}  // namespace tc
