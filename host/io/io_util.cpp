#include "io/io_util.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <system_error>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace tc::io {

std::string load_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not a mesh file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path, "cannot determine the file size");
  in.seekg(0, std::ios::beg);
  std::string data(static_cast<size_t>(size), '\0');
  if (size > 0 && !in.read(data.data(), size)) throw InputError(path, "read error");
  return data;
}

// ---------------------------------------------------------------- FileBytes

namespace {
size_t file_bytes_step = size_t(16) << 20;
}  // namespace

void FileBytes::set_step(size_t step) { file_bytes_step = std::max<size_t>(step, 1); }

FileBytes::FileBytes(const std::string& path) : step_(file_bytes_step), next_(file_bytes_step) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not a mesh file");
  const int fd = ::open(path.c_str(), O_RDONLY);
  struct stat st {};
  if (fd >= 0 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    void* p = ::mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
    if (p != MAP_FAILED) {
      map_ = p;
      size_ = size_t(st.st_size);
      ::madvise(map_, size_, MADV_SEQUENTIAL);
      view_ = std::string_view(static_cast<const char*>(map_), size_);
    }
  }
  if (fd >= 0) ::close(fd);
  if (!map_) {  // empty, not a regular file, or not mappable: read as before
    owned_ = load_file(path);
    view_ = owned_;
  }
}

FileBytes::~FileBytes() {
  if (map_) ::munmap(map_, size_);
}

void FileBytes::release(size_t pos) {
  next_ = pos + step_;
  if (!map_) return;
  // whole pages, a step behind (a reader may look back a little: it would only read again)
  const size_t page = size_t(::sysconf(_SC_PAGESIZE));
  // never past the mapping's last page: what lies beyond is another mapping's (madvise would
  // drop its pages too, a library's relocated data among them)
  const size_t end = std::min(pos > step_ ? (pos - step_) / page * page : 0, (size_ + page - 1) / page * page);
  if (end <= released_) return;
  ::madvise(static_cast<char*>(map_) + released_, end - released_, MADV_DONTNEED);
  released_ = end;
}

// ---------------------------------------------------------------- TextCursor

void TextCursor::skip_space() {
  if (release_) release_->done_before(pos_);
  while (pos_ < text_.size()) {
    char c = text_[pos_];
    if (c == '\n') {
      ++line_;
    } else if (c != ' ' && c != '\t' && c != '\r' && c != '\f' && c != '\v') {
      break;
    }
    ++pos_;
  }
}

bool TextCursor::at_end() {
  skip_space();
  return pos_ >= text_.size();
}

std::string_view TextCursor::next_token() {
  skip_space();
  if (pos_ >= text_.size()) fail("unexpected end of file");
  size_t start = pos_;
  while (pos_ < text_.size()) {
    char c = text_[pos_];
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') break;
    ++pos_;
  }
  return text_.substr(start, pos_ - start);
}

std::string_view TextCursor::peek_token() {
  size_t p = pos_;
  int64_t l = line_;
  std::string_view t = at_end() ? std::string_view() : next_token();
  pos_ = p;
  line_ = l;
  return t;
}

std::string_view TextCursor::rest_of_line() {
  size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  std::string_view r = text_.substr(start, pos_ - start);
  if (!r.empty() && r.back() == '\r') r.remove_suffix(1);
  return r;
}

void TextCursor::skip_line() {
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
}

static std::string show(std::string_view tok) {
  std::string s(tok.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  if (tok.size() > 40) s += "...";
  return "'" + s + "'";
}

int64_t TextCursor::next_int() {
  std::string_view t = next_token();
  int64_t v = 0;
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (b != e && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, v);
  if (ec == std::errc::result_out_of_range) fail("integer out of range: " + show(t));
  if (ec != std::errc() || p != e) fail("expected an integer, found " + show(t));
  return v;
}

double TextCursor::next_double() {
  std::string_view t = next_token();
  double v = 0;
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (b != e && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, v);
  if (ec == std::errc::result_out_of_range) {
    // Denormals and overflow: fall back to strtod, which saturates / rounds.
    std::string s(t);
    v = std::strtod(s.c_str(), nullptr);
  } else if (ec != std::errc() || p != e) {
    // Fortran-style exponents ("1.0D+00") appear in some Medit files.
    std::string s(t);
    std::replace(s.begin(), s.end(), 'D', 'e');
    std::replace(s.begin(), s.end(), 'd', 'e');
    char* end = nullptr;
    v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size()) fail("expected a number, found " + show(t));
  }
  return v;
}

namespace {
thread_local bool lenient_reading = false;
}
bool lenient() { return lenient_reading; }
Lenient::Lenient(bool on) : before(lenient_reading) { lenient_reading = on; }
Lenient::~Lenient() { lenient_reading = before; }

double TextCursor::next_finite_double(const char* what) {
  double v = next_double();
  if (!std::isfinite(v) && !lenient()) fail(std::string("non-finite ") + what + " (NaN or infinity)");
  return v;
}

int64_t TextCursor::next_count(const char* what, int64_t max_count) {
  int64_t n = next_int();
  if (n < 0) fail(std::string("negative ") + what + ": " + std::to_string(n));
  if (n > max_count)
    fail(std::string(what) + " " + std::to_string(n) + " is more than the rest of the file can hold");
  return n;
}

void TextCursor::expect(std::string_view token) {
  std::string_view t = next_token();
  if (t != token) fail("expected '" + std::string(token) + "', found " + show(t));
}

void TextCursor::set_pos(size_t p) {
  pos_ = std::min(p, text_.size());
  line_ = 1 + std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(pos_), '\n');
}

// ---------------------------------------------------------------- AtomicFile

std::filesystem::path require_output_folder(const std::string& path) {
  const std::filesystem::path p(path);
  std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw OutputError(path + ": folder '" + dir.string() + "' does not exist");
  return dir;
}

AtomicFile::AtomicFile(const std::string& path, bool binary) : path_(path) {
  const std::filesystem::path dir = require_output_folder(path);
  std::random_device rd;
  // appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) on "." + std::string&&
  std::string name = ".";
  name += std::filesystem::path(path).filename().string();
  name += ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(rd() % 1000000);
  tmp_ = (dir / name).string();
  out_.open(tmp_, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
  if (!out_) throw OutputError(path + ": cannot create a temporary file in '" + dir.string() + "': " + std::strerror(errno));
  out_.exceptions(std::ios::goodbit);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) throw OutputError(path_ + ": write failed (disk full or I/O error)");
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) throw OutputError(path_ + ": cannot rename the temporary file onto the target: " + ec.message());
  committed_ = true;
}

void commit_all(std::initializer_list<AtomicFile*> files) {
  for (AtomicFile* f : files) f->commit();
}

// ---------------------------------------------------------------- numbers

void append_double(std::string& out, double v) {
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  if (ec != std::errc()) {
    int n = std::snprintf(buf, sizeof buf, "%.17g", v);
    out.append(buf, static_cast<size_t>(n));
    return;
  }
  out.append(buf, p);
}

std::string format_double(double v) {
  std::string s;
  append_double(s, v);
  return s;
}

void append_int(std::string& out, int64_t v) {
  char buf[24];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  (void)ec;
  out.append(buf, p);
}

// ---------------------------------------------------------------- base64 / zlib

static const char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string base64_encode(std::string_view in) {
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t n = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    out += kB64[(n >> 18) & 63];
    out += kB64[(n >> 12) & 63];
    out += kB64[(n >> 6) & 63];
    out += kB64[n & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t n = uint8_t(in[i]) << 16;
    out += kB64[(n >> 18) & 63];
    out += kB64[(n >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t n = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
    out += kB64[(n >> 18) & 63];
    out += kB64[(n >> 12) & 63];
    out += kB64[(n >> 6) & 63];
    out += '=';
  }
  return out;
}

bool base64_decode(std::string_view text, std::string& out) {
  static int8_t table[256];
  static bool init = [] {
    std::fill(std::begin(table), std::end(table), int8_t(-1));
    for (int i = 0; i < 64; ++i) table[uint8_t(kB64[i])] = int8_t(i);
    return true;
  }();
  (void)init;
  out.clear();
  out.reserve(text.size() / 4 * 3);
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=' ) break;
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    int8_t d = table[uint8_t(c)];
    if (d < 0) return false;
    acc = (acc << 6) | uint32_t(d);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((acc >> bits) & 0xFF);
    }
  }
  return true;
}

bool zlib_inflate(std::string_view in, std::string& out, size_t expected_size) {
  out.resize(expected_size);
  uLongf dest_len = static_cast<uLongf>(expected_size);
  int rc = ::uncompress(reinterpret_cast<Bytef*>(out.data()), &dest_len,
                        reinterpret_cast<const Bytef*>(in.data()), static_cast<uLong>(in.size()));
  if (rc != Z_OK || dest_len != expected_size) return false;
  return true;
}

// ---------------------------------------------------------------- paths

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string replace_extension(const std::string& path, const std::string& ext) {
  std::filesystem::path p(path);
  p.replace_extension(ext);
  return p.string();
}

}  // namespace tc::io
