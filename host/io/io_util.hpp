// Shared machinery for the file-format readers and writers.
//
// Why our own parsers: the formats are simple, the shared readers we could use (meshio is
// Python, VTK is a huge dependency, gmsh's API is GPL and reads only its own format) do not
// give what we need here: one-line errors with line or byte offset, no allocation from an
// unchecked count, and speed on 1M-tet binary files.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "tetcollapse/error.hpp"
#include "tetcollapse/io.hpp"

namespace tc::io {

// Whole file in memory. Throws InputError when it cannot be opened.
std::string load_file(const std::string& path);

// A file's bytes, mapped read-only (read into memory where it cannot be mapped), which a reader
// gives back behind itself as it goes (the cursors' release_through): the pages before where it
// is are dropped from the process (looked at again, they are read from the file again), so a
// reader's peak memory is the mesh it builds and a window of the file, not the whole file.
// Throws InputError as load_file. (As with any mapped reading, a file cut short by another
// process while it is read ends the process with SIGBUS; load_file's copy did not have this.)
class FileBytes {
 public:
  explicit FileBytes(const std::string& path);
  ~FileBytes();
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  std::string_view view() const { return view_; }
  // The reader is done with the bytes before `pos` (a hint): every `step` bytes, the pages more
  // than a step behind are given back.
  void done_before(size_t pos) {
    if (pos >= next_) release(pos);
  }
  // The reader is done with all of it (e.g. it copied it).
  void done() { release(size_ + 2 * step_); }
  // The reader starts again from the beginning (after a scan that gave the pages back).
  void rewind() { released_ = 0, next_ = step_; }
  // The step of the files opened after (tests make it small); 16 MB.
  static void set_step(size_t step);

 private:
  void release(size_t pos);
  std::string owned_;
  void* map_ = nullptr;
  size_t size_ = 0, released_ = 0, step_ = 0, next_ = 0;
  std::string_view view_;
};

// Reads whitespace-separated tokens while tracking the line number, for error messages.
class TextCursor {
 public:
  TextCursor(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  bool at_end();                      // skips whitespace; true when nothing is left
  std::string_view next_token();      // throws "unexpected end of file" at the end
  std::string_view peek_token();      // does not consume
  std::string_view rest_of_line();    // from the current position to end of line (consumed)
  void skip_line();                   // to the start of the next line
  int64_t next_int();                 // integer token; errors name the token
  double next_double();               // finite or not: the caller decides
  double next_finite_double(const char* what);  // rejects NaN / inf
  // A count read from the file, checked: 0 <= n <= max_count (else an error naming what).
  int64_t next_count(const char* what, int64_t max_count);
  void expect(std::string_view token);  // next token must equal `token`

  int64_t line() const { return line_; }
  size_t pos() const { return pos_; }
  void set_pos(size_t p);               // recomputes the line number
  std::string_view text() const { return text_; }
  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const std::string& reason) const { throw InputError(file_, line_, reason); }
  // Gives the pages of `f` (whose view this cursor reads) back behind the cursor as it goes.
  void release_through(FileBytes* f) { release_ = f; }

  // Upper bound for a count of items that each take at least `min_chars` characters.
  int64_t max_items(int64_t min_chars) const {
    return static_cast<int64_t>((text_.size() - pos_) / (min_chars > 0 ? min_chars : 1)) + 1;
  }

 private:
  void skip_space();
  std::string_view text_;
  std::string file_;
  size_t pos_ = 0;
  int64_t line_ = 1;
  FileBytes* release_ = nullptr;
};

// Reads binary data with bounds checks; errors name the byte offset.
class BinaryCursor {
 public:
  BinaryCursor(std::string_view data, std::string file, bool swap = false)
      : data_(data), file_(std::move(file)), swap_(swap) {}

  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    if (swap_) v = byteswap_value(v);
    if (release_) release_->done_before(pos_);
    return v;
  }
  // Gives the pages of `f` (whose view this cursor reads) back behind the cursor as it goes.
  void release_through(FileBytes* f) { release_ = f; }
  // Reads n items into out (resized), checked against the bytes left.
  template <class T>
  void get_array(std::vector<T>& out, int64_t n) {
    if (n < 0 || static_cast<uint64_t>(n) > remaining() / sizeof(T))
      fail("array of " + std::to_string(n) + " items runs past the end of the file");
    out.resize(static_cast<size_t>(n));
    if (n) std::memcpy(out.data(), data_.data() + pos_, static_cast<size_t>(n) * sizeof(T));
    pos_ += static_cast<size_t>(n) * sizeof(T);
    if (release_) release_->done_before(pos_);
    if (swap_)
      for (auto& v : out) v = byteswap_value(v);
  }
  void skip(size_t n) { need(n); pos_ += n; }
  void need(size_t n) const {
    if (n > remaining()) fail("unexpected end of file (need " + std::to_string(n) + " more bytes)");
  }
  size_t remaining() const { return data_.size() - pos_; }
  size_t pos() const { return pos_; }
  void set_pos(size_t p) { pos_ = p; }
  bool swapping() const { return swap_; }
  void set_swap(bool s) { swap_ = s; }
  std::string_view data() const { return data_; }
  [[noreturn]] void fail(const std::string& reason) const {
    throw InputError::at_byte(file_, static_cast<int64_t>(pos_), reason);
  }
  [[noreturn]] void fail_at(size_t offset, const std::string& reason) const {
    throw InputError::at_byte(file_, static_cast<int64_t>(offset), reason);
  }

  template <class T>
  static T byteswap_value(T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

 private:
  std::string_view data_;
  std::string file_;
  size_t pos_ = 0;
  bool swap_ = false;
  FileBytes* release_ = nullptr;
};

// The format write_mesh writes `path` in: f, or when Auto the one its extension names (an
// unknown one: OutputError).
Format output_format(const std::string& path, Format f);

// The folder `path` is to be written in; throws OutputError unless it exists (AtomicFile's
// first check, also made before a long run by the CLI).
std::filesystem::path require_output_folder(const std::string& path);

// A file written under a temporary name in the target's folder and renamed onto the
// target by commit(). Destroyed without commit(), the temporary is removed, so a failed
// write never leaves a half-written file behind. Throws OutputError.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path, bool binary = true);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  void write(const void* data, size_t n) { out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(n)); }
  void commit();  // flush, check, rename
  const std::string& path() const { return path_; }

 private:
  std::string path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

// Commits several files together (all or, on the first failure, as few as possible).
void commit_all(std::initializer_list<AtomicFile*> files);

// The checker's reading (ReadOptions::as_is), on this thread while a Lenient lives: the readers
// keep non-finite coordinates and out-of-range vertex indices for tc::check_mesh to report.
bool lenient();
struct Lenient {
  explicit Lenient(bool on);
  ~Lenient();
  bool before;
};

// Shortest text that reads back as exactly the same double ("%.17g" style, shortest form).
std::string format_double(double v);
void append_double(std::string& out, double v);
void append_int(std::string& out, int64_t v);

// Base64 (for VTU) and zlib helpers.
std::string base64_encode(std::string_view bytes);
// Decodes; returns false on malformed input.
bool base64_decode(std::string_view text, std::string& out);
// Inflates zlib data of known size; returns false on failure.
bool zlib_inflate(std::string_view in, std::string& out, size_t expected_size);

// Lower-case file extension including the dot (".msh"), "" when none.
std::string extension_of(const std::string& path);
// Path with its extension replaced (".sol", ".ele", ...).
std::string replace_extension(const std::string& path, const std::string& ext);

}  // namespace tc::io
