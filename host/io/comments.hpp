// '#' comments in the text formats (Medit .mesh/.sol, TetGen .node/.ele/.face).
#pragma once

#include <string>
#include <string_view>

namespace tc::io {

// Returns the text with every comment (from '#' to the end of its line) blanked out with
// spaces, so that TextCursor sees only data while line numbers stay right. When the text
// has no '#', the original is returned and `storage` is left untouched (no copy).
inline std::string_view blank_comments(std::string_view text, std::string& storage) {
  if (text.find('#') == std::string_view::npos) return text;
  storage.assign(text);
  bool in_comment = false;
  for (char& ch : storage) {
    if (ch == '\n') in_comment = false;
    else if (ch == '#') in_comment = true;
    if (in_comment) ch = ' ';
  }
  return storage;
}

}  // namespace tc::io
