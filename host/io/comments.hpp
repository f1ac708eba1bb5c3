// '#' comments in the text formats (Medit .mesh/.sol, TetGen .node/.ele/.face).
#pragma once

#include <string>
#include <string_view>

#include "io/io_util.hpp"

namespace tc::io {

// Returns the text with every comment (from '#' to the end of its line) blanked out with
// spaces, so that TextCursor sees only data while line numbers stay right. When the text
// has no '#', the original is returned and `storage` is left untouched (no copy).
// With `file` (whose view `text` is), the scan for a '#' gives the pages it has looked at back
// behind itself, so that a file without comments is not all resident before it is parsed.
inline std::string_view blank_comments(std::string_view text, std::string& storage, FileBytes* file = nullptr) {
  bool any = false;
  for (size_t at = 0; at < text.size() && !any; at += size_t(1) << 20) {
    any = text.substr(at, size_t(1) << 20).find('#') != std::string_view::npos;
    if (file) file->done_before(at);
  }
  if (file) file->rewind();  // the cursor reads it again from the start
  if (!any) return text;
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
