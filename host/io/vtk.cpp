// VTK legacy format (.vtk), versions 2.0 to 5.1, ASCII and BINARY (big-endian), DATASET
// UNSTRUCTURED_GRID. Format reference: "VTK File Formats" (VTK User's Guide), and
// vtkDataReader / vtkDataWriter for the details the guide leaves open (5.1 OFFSETS /
// CONNECTIVITY cells, METADATA blocks, NULL_ARRAY, %20 in names).
//
// Why our own parser: see io_util.hpp. The header lines are text even in BINARY files, so
// the reader walks the file with a TextCursor and switches to a BinaryCursor for each data
// block; in BINARY files every error names a byte offset, in ASCII files a line.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "io/io_util.hpp"
#include "io/vtk_common.hpp"
#include "tetcollapse/io.hpp"

namespace tc {

namespace {

using io::TextCursor;
using io::vtk::NumType;
using io::vtk::RawArray;

std::string upper(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = char(std::toupper(static_cast<unsigned char>(c)));
  return r;
}

// vtkDataWriter encodes special characters of names as %XX (a space is %20).
std::string decode_name(std::string_view s) {
  std::string r;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      r += char(std::stoi(std::string(s.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      r += s[i];
    }
  }
  return r;
}

std::string encode_name(const std::string& s) {
  static const char* hex = "0123456789ABCDEF";
  std::string r;
  for (unsigned char c : s) {
    if (c <= ' ' || c == '%' || c >= 127) {
      r += '%';
      r += hex[c >> 4];
      r += hex[c & 15];
    } else {
      r += char(c);
    }
  }
  return r.empty() ? std::string("unnamed") : r;
}

// A position in the file, for errors that are found after a block was read.
struct Where {
  int64_t line = -1;
  int64_t byte = -1;
};

class LegacyReader {
 public:
  LegacyReader(const std::string& path, ReadNotes& notes) : file_(path), notes_(notes), cur_("", path) {}

  Mesh read() {
    data_ = io::load_file(file_);
    try {
      parse();
    } catch (const InputError& e) {
      // TextCursor reports lines relative to the current block; in BINARY files, name
      // the byte offset instead.
      if (binary_ && e.line() >= 0) throw InputError::at_byte(file_, int64_t(base_ + cur_.pos()), e.reason());
      throw;
    }
    return std::move(mesh_);
  }

 private:
  std::string file_;
  ReadNotes& notes_;
  std::string data_;
  bool binary_ = false;
  size_t base_ = 0;  // offset of cur_'s text in data_
  TextCursor cur_;

  Mesh mesh_;
  bool have_points_ = false, have_cells_ = false, have_types_ = false;
  Where cells_where_;
  io::vtk::Cells cells_;
  std::vector<RawArray> point_arrays_, cell_arrays_;

  enum class Section { None, Point, Cell } section_ = Section::None;
  int64_t section_count_ = 0;
  Where section_where_;

  [[noreturn]] void fail(const std::string& reason) const {
    if (binary_) throw InputError::at_byte(file_, int64_t(base_ + cur_.pos()), reason);
    throw InputError(file_, cur_.line(), reason);
  }
  [[noreturn]] void fail_at(const Where& w, const std::string& reason) const {
    if (w.byte >= 0 && binary_) throw InputError::at_byte(file_, w.byte, reason);
    throw InputError(file_, w.line, reason);
  }
  Where here() {
    cur_.at_end();  // skip blanks so the position is that of the next token
    return Where{cur_.line(), int64_t(base_ + cur_.pos())};
  }

  // ------------------------------------------------------------ header

  std::string_view header_line(size_t& pos, const char* what) {
    if (pos >= data_.size()) {
      if (data_.empty()) throw InputError(file_, "empty file");
      throw InputError(file_, int64_t(std::count(data_.begin(), data_.end(), '\n') + 1),
                       std::string("unexpected end of file: missing the ") + what + " line");
    }
    size_t end = data_.find('\n', pos);
    if (end == std::string::npos) end = data_.size();
    std::string_view l(data_.data() + pos, end - pos);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    pos = std::min(end + 1, data_.size());
    return l;
  }

  void parse_header() {
    size_t pos = 0;
    std::string_view l1 = header_line(pos, "'# vtk DataFile Version' header");
    const std::string_view key = "vtk DataFile Version";
    size_t k = upper(l1).find(upper(key));
    if (l1.empty() || l1[0] != '#' || k == std::string::npos)
      throw InputError(file_, 1, "not a VTK legacy file (the first line must be '# vtk DataFile Version x.y')");
    std::string ver(l1.substr(k + key.size()));
    ver.erase(0, ver.find_first_not_of(" \t"));
    ver.erase(ver.find_last_not_of(" \t") + 1);
    int major = -1, minor = -1;
    size_t dot = ver.find('.');
    if (dot != std::string::npos && dot > 0 && dot + 1 < ver.size() &&
        std::all_of(ver.begin(), ver.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '.'; })) {
      major = std::atoi(ver.substr(0, dot).c_str());
      minor = std::atoi(ver.substr(dot + 1).c_str());
    }
    bool known = (major >= 2 && major <= 4) || (major == 5 && minor >= 0 && minor <= 1);
    if (!known)
      throw InputError(file_, 1, "unsupported VTK legacy version '" + ver + "' (supported: 2.0 to 5.1)");
    new_cells_ = major >= 5;
    header_line(pos, "title");
    std::string mode = upper(header_line(pos, "ASCII/BINARY"));
    mode.erase(mode.find_last_not_of(" \t") + 1);
    mode.erase(0, mode.find_first_not_of(" \t"));
    if (mode == "ASCII") binary_ = false;
    else if (mode == "BINARY") binary_ = true;
    else throw InputError(file_, 3, "expected ASCII or BINARY on line 3, found '" + mode.substr(0, 40) + "'");
    // One cursor over the whole file for ASCII (true line numbers); for BINARY a cursor
    // restarted after each binary block (positions are reported as byte offsets).
    base_ = binary_ ? pos : 0;
    cur_ = TextCursor(std::string_view(data_).substr(base_), file_);
    if (!binary_) cur_.set_pos(pos);
  }
  bool new_cells_ = false;

  // ------------------------------------------------------------ data blocks

  // Reads n values of file type t into out. In BINARY files the data starts on the line
  // after the cursor; the text cursor restarts after the block.
  template <class T>
  void read_values(NumType t, int64_t n, std::vector<T>& out, const std::string& what) {
    if (!binary_) {
      if (n < 0 || n > cur_.max_items(2))
        fail(what + ": " + std::to_string(n) + " values are more than the rest of the file can hold");
      out.resize(static_cast<size_t>(n));
      const bool int_type = io::vtk::type_is_integer(t);
      for (auto& v : out) {
        if constexpr (std::is_integral_v<T>) {
          if (int_type) {
            v = cur_.next_int();
          } else {
            double d = cur_.next_double();
            if (!(d == std::floor(d) && std::abs(d) < 9.0e18)) fail(what + ": expected an integer value");
            v = static_cast<T>(d);
          }
        } else {
          v = static_cast<T>(cur_.next_double());
        }
      }
      return;
    }
    cur_.skip_line();
    const size_t start = base_ + cur_.pos();
    const size_t size = io::vtk::type_size(t);
    if (n < 0 || static_cast<uint64_t>(n) > (data_.size() - start) / size)
      throw InputError::at_byte(file_, int64_t(start),
                                what + ": " + std::to_string(n) + " values of " + std::to_string(size) +
                                    " bytes run past the end of the file");
    out.resize(static_cast<size_t>(n));
    const int64_t bad = io::vtk::convert_raw(data_.data() + start, t, static_cast<size_t>(n), io::vtk::kHostLittle, out.data());
    if (bad >= 0)
      throw InputError::at_byte(file_, int64_t(start + static_cast<size_t>(bad) * size),
                                what + ": value " + std::to_string(bad + 1) + " is not an integer");
    base_ = start + static_cast<size_t>(n) * size;
    cur_ = TextCursor(std::string_view(data_).substr(base_), file_);
  }

  NumType read_type(const std::string& what) {
    std::string_view tok = cur_.next_token();
    NumType t;
    if (!io::vtk::parse_legacy_type(tok, t))
      fail(what + ": unknown data type '" + std::string(tok.substr(0, 40)) + "'");
    return t;
  }

  // METADATA blocks (VTK >= 8) end at the first empty line.
  void skip_metadata() {
    cur_.skip_line();
    while (cur_.pos() < cur_.text().size()) {
      std::string_view l = cur_.rest_of_line();
      cur_.skip_line();
      if (l.find_first_not_of(" \t\r") == std::string_view::npos) return;
    }
  }
  void skip_optional_metadata() {
    if (!cur_.at_end() && upper(cur_.peek_token()) == "METADATA") {
      cur_.next_token();
      skip_metadata();
    }
  }

  int64_t count(const char* what, int64_t max = std::numeric_limits<int32_t>::max()) {
    int64_t n = cur_.next_int();
    if (n < 0) fail(std::string("negative ") + what + ": " + std::to_string(n));
    if (n > max) fail(std::string(what) + " " + std::to_string(n) + " is too large");
    return n;
  }

  void add_array(RawArray a) {
    if (section_ == Section::Point) point_arrays_.push_back(std::move(a));
    else if (section_ == Section::Cell) cell_arrays_.push_back(std::move(a));
    // Field data of the whole dataset (before POINT_DATA / CELL_DATA) is not per entity: dropped.
  }

  void read_attribute(const std::string& kw) {
    if (section_ == Section::None) fail(kw + " outside POINT_DATA / CELL_DATA");
    const std::string name = decode_name(cur_.next_token());
    const std::string what = kw + " '" + name + "'";
    int comps = 1;
    NumType t = NumType::Float32;
    if (kw == "SCALARS") {
      t = read_type(what);
      std::string_view rest = cur_.rest_of_line();
      size_t b = rest.find_first_not_of(" \t");
      if (b != std::string_view::npos) {
        std::string r(rest.substr(b));
        r.erase(r.find_last_not_of(" \t") + 1);
        char* end = nullptr;
        long c = std::strtol(r.c_str(), &end, 10);
        if (end != r.c_str() + r.size() || c < 1 || c > 4)
          fail(what + ": number of components must be 1 to 4, found '" + r.substr(0, 20) + "'");
        comps = int(c);
      }
      if (!cur_.at_end() && upper(cur_.peek_token()) == "LOOKUP_TABLE") {
        cur_.next_token();
        cur_.next_token();
      }
    } else if (kw == "VECTORS" || kw == "NORMALS") {
      t = read_type(what);
      comps = 3;
    } else if (kw == "TENSORS" || kw == "TENSORS6") {
      t = read_type(what);
      comps = kw == "TENSORS" ? 9 : 6;
    } else if (kw == "TEXTURE_COORDINATES") {
      comps = int(count("texture coordinate dimension", 3));
      if (comps < 1) fail(what + ": dimension must be 1 to 3");
      t = read_type(what);
    } else if (kw == "COLOR_SCALARS") {
      comps = int(count("number of color components", 4));
      if (comps < 1) fail(what + ": number of components must be 1 to 4");
      t = binary_ ? NumType::UInt8 : NumType::Float32;
    }
    RawArray a;
    a.name = name;
    a.components = comps;
    a.integer = io::vtk::type_is_integer(t);
    read_values(t, section_count_ * comps, a.values, what);
    skip_optional_metadata();
    add_array(std::move(a));
  }

  void read_field() {
    cur_.next_token();  // the field's name (FieldData)
    const int64_t narrays = count("number of FIELD arrays", 1 << 20);
    for (int64_t i = 0; i < narrays; ++i) {
      std::string_view tok = cur_.next_token();
      if (upper(tok) == "NULL_ARRAY") continue;
      RawArray a;
      a.name = decode_name(tok);
      const std::string what = "FIELD array '" + a.name + "'";
      int64_t comps = count("number of components", 1 << 16);
      int64_t tuples = count("number of tuples", std::numeric_limits<int64_t>::max() / (1 << 16));
      NumType t = read_type(what);
      if (comps < 1) fail(what + ": number of components must be at least 1");
      a.components = int(comps);
      a.integer = io::vtk::type_is_integer(t);
      if (section_ != Section::None && tuples != section_count_)
        fail(what + " has " + std::to_string(tuples) + " tuples, but the " +
             (section_ == Section::Point ? "POINT_DATA" : "CELL_DATA") + " count is " +
             std::to_string(section_count_));
      read_values(t, tuples * comps, a.values, what);
      skip_optional_metadata();
      add_array(std::move(a));
    }
  }

  void read_points() {
    if (have_points_) fail("second POINTS section");
    const int64_t n = count("number of points");
    NumType t = read_type("POINTS");
    Where w = Where{cur_.line(), int64_t(base_ + cur_.pos())};
    read_values(t, 3 * n, mesh_.points, "POINTS");
    int64_t bad = io::vtk::first_non_finite(mesh_.points);
    if (bad >= 0 && !io::lenient()) fail_at(w, "point " + std::to_string(bad / 3) + " has a non-finite coordinate (NaN or infinity)");
    have_points_ = true;
    skip_optional_metadata();
  }

  void read_cells() {
    if (have_cells_) fail("second CELLS section");
    cells_where_ = Where{cur_.line(), int64_t(base_ + cur_.pos())};
    const int64_t n = count("number of cells", std::numeric_limits<int64_t>::max());
    const int64_t size = count("CELLS list size", std::numeric_limits<int64_t>::max());
    if (new_cells_) {
      // 5.x: CELLS <offsets count> <connectivity count>, then OFFSETS and CONNECTIVITY arrays.
      cur_.expect("OFFSETS");
      NumType t = read_type("OFFSETS");
      read_values(t, n, cells_.offsets, "OFFSETS");
      cur_.expect("CONNECTIVITY");
      t = read_type("CONNECTIVITY");
      read_values(t, size, cells_.conn, "CONNECTIVITY");
      if (n == 0) cells_.offsets.push_back(0);
      if (cells_.offsets[0] != 0) fail_at(cells_where_, "OFFSETS must start with 0");
      for (size_t i = 1; i < cells_.offsets.size(); ++i)
        if (cells_.offsets[i] < cells_.offsets[i - 1])
          fail_at(cells_where_, "OFFSETS decrease at cell " + std::to_string(i - 1));
      if (cells_.offsets.back() != size)
        fail_at(cells_where_, "the last offset is " + std::to_string(cells_.offsets.back()) +
                                  ", but CONNECTIVITY has " + std::to_string(size) + " values");
    } else {
      // Before 5.0: CELLS <cells> <size>, then per cell its point count and points.
      if (n > size) fail_at(cells_where_, "CELLS: " + std::to_string(n) + " cells cannot fit in a list of " +
                                              std::to_string(size) + " values");
      std::vector<int64_t> list;
      read_values(NumType::Int32, size, list, "CELLS");
      cells_.offsets.assign(1, 0);
      cells_.offsets.reserve(static_cast<size_t>(n) + 1);
      cells_.conn.reserve(static_cast<size_t>(size - n));
      size_t p = 0;
      for (int64_t c = 0; c < n; ++c) {
        if (p >= list.size())
          fail_at(cells_where_, "CELLS list of " + std::to_string(size) + " values ends at cell " + std::to_string(c) +
                                    " of " + std::to_string(n));
        int64_t k = list[p++];
        if (k < 0 || static_cast<uint64_t>(k) > list.size() - p)
          fail_at(cells_where_, "cell " + std::to_string(c) + " has " + std::to_string(k) +
                                    " points, which runs past the CELLS list size " + std::to_string(size));
        cells_.conn.insert(cells_.conn.end(), list.begin() + p, list.begin() + p + k);
        p += static_cast<size_t>(k);
        cells_.offsets.push_back(static_cast<int64_t>(cells_.conn.size()));
      }
      if (p != list.size())
        fail_at(cells_where_, "CELLS size is " + std::to_string(size) + ", but the " + std::to_string(n) +
                                  " cells use " + std::to_string(p) + " values");
    }
    have_cells_ = true;
    skip_optional_metadata();
  }

  void read_cell_types() {
    if (have_types_) fail("second CELL_TYPES section");
    const int64_t n = count("number of cell types", std::numeric_limits<int64_t>::max());
    if (have_cells_ && n != int64_t(cells_.offsets.size()) - 1)
      fail("CELL_TYPES has " + std::to_string(n) + " entries, but CELLS has " +
           std::to_string(cells_.offsets.size() - 1) + " cells");
    read_values(NumType::Int32, n, cells_.types, "CELL_TYPES");
    have_types_ = true;
    skip_optional_metadata();
  }

  void start_section(Section s) {
    Where w = here();
    const char* kw = s == Section::Point ? "POINT_DATA" : "CELL_DATA";
    int64_t n = count(kw, int64_t(1) << 40);
    int64_t expected = s == Section::Point ? (have_points_ ? mesh_.num_vertices() : -1)
                                           : (have_cells_ ? int64_t(cells_.offsets.size()) - 1 : -1);
    if (expected >= 0 && n != expected)
      fail_at(w, std::string(kw) + " " + std::to_string(n) + " does not match the " +
                     (s == Section::Point ? "number of points " : "number of cells ") + std::to_string(expected));
    section_ = s;
    section_count_ = n;
    section_where_ = w;
    (s == Section::Point ? point_where_ : cell_where_) = w;
    (s == Section::Point ? point_count_ : cell_count_) = n;
  }
  Where point_where_, cell_where_;
  int64_t point_count_ = -1, cell_count_ = -1;

  void parse() {
    parse_header();
    if (cur_.at_end()) fail("unexpected end of file: no DATASET");
    std::string kw = upper(cur_.next_token());
    if (kw == "FIELD") {
      section_ = Section::None;
      read_field();
      kw = upper(cur_.next_token());
    }
    if (kw != "DATASET") fail("expected DATASET, found '" + kw.substr(0, 40) + "'");
    std::string type = upper(cur_.next_token());
    if (type != "UNSTRUCTURED_GRID")
      fail("DATASET " + type.substr(0, 40) + " is not supported (only UNSTRUCTURED_GRID holds tetrahedra)");
    while (!cur_.at_end()) {
      kw = upper(cur_.next_token());
      if (kw == "POINTS") read_points();
      else if (kw == "CELLS") read_cells();
      else if (kw == "CELL_TYPES") read_cell_types();
      else if (kw == "POINT_DATA") start_section(Section::Point);
      else if (kw == "CELL_DATA") start_section(Section::Cell);
      else if (kw == "FIELD") read_field();
      else if (kw == "SCALARS" || kw == "VECTORS" || kw == "NORMALS" || kw == "TENSORS" || kw == "TENSORS6" ||
               kw == "TEXTURE_COORDINATES" || kw == "COLOR_SCALARS")
        read_attribute(kw);
      else if (kw == "LOOKUP_TABLE") skip_lookup_table();
      else if (kw == "METADATA") skip_metadata();
      else if (kw == "GLOBAL_IDS" || kw == "PEDIGREE_IDS") {
        // vtkIdType-like id arrays: keep them as integer arrays.
        if (section_ == Section::None) fail(kw + " outside POINT_DATA / CELL_DATA");
        RawArray a;
        a.name = decode_name(cur_.next_token());
        NumType t = read_type(kw);
        a.integer = io::vtk::type_is_integer(t);
        read_values(t, section_count_, a.values, kw);
        add_array(std::move(a));
      } else fail("unknown keyword '" + kw.substr(0, 40) + "'");
    }
    finish();
  }

  void skip_lookup_table() {
    cur_.next_token();  // table name
    int64_t n = count("lookup table size", std::numeric_limits<int64_t>::max() / 4);
    std::vector<double> dummy;
    read_values(binary_ ? NumType::UInt8 : NumType::Float32, 4 * n, dummy, "LOOKUP_TABLE");
  }

  void finish() {
    if (!have_points_) fail("no POINTS section");
    if (mesh_.num_vertices() > std::numeric_limits<int32_t>::max()) fail("more than 2^31-1 points");
    if (have_cells_ && !have_types_) fail("CELLS without CELL_TYPES");
    if (!have_cells_ && have_types_) fail("CELL_TYPES without CELLS");
    if (!have_cells_) cells_.offsets.assign(1, 0);
    if (cells_.types.size() + 1 != cells_.offsets.size())
      fail_at(cells_where_, "CELL_TYPES has " + std::to_string(cells_.types.size()) + " entries, but CELLS has " +
                                std::to_string(cells_.offsets.size() - 1) + " cells");
    if (point_count_ >= 0 && point_count_ != mesh_.num_vertices())
      fail_at(point_where_, "POINT_DATA " + std::to_string(point_count_) + " does not match the number of points " +
                                std::to_string(mesh_.num_vertices()));
    if (cell_count_ >= 0 && cell_count_ != cells_.num_cells())
      fail_at(cell_where_, "CELL_DATA " + std::to_string(cell_count_) + " does not match the number of cells " +
                               std::to_string(cells_.num_cells()));
    io::vtk::assemble(mesh_, notes_, cells_, point_arrays_, cell_arrays_,
                      [&](const std::string& why) { fail_at(cells_where_, "CELLS: " + why); });
  }
};

// ---------------------------------------------------------------- writer

template <class T>
void append_big_endian(std::string& out, const T* v, size_t n) {
  const size_t at = out.size();
  out.resize(at + n * sizeof(T));
  std::memcpy(out.data() + at, v, n * sizeof(T));
  if constexpr (io::vtk::kHostLittle && sizeof(T) > 1) {
    char* p = out.data() + at;
    for (size_t i = 0; i < n; ++i, p += sizeof(T)) std::reverse(p, p + sizeof(T));
  }
}

// Values as text, `per_line` to a line, or as big-endian binary followed by a newline.
void append_doubles(std::string& out, const std::vector<double>& v, size_t per_line, bool binary) {
  if (binary) {
    append_big_endian(out, v.data(), v.size());
    out += '\n';
    return;
  }
  for (size_t i = 0; i < v.size(); ++i) {
    io::append_double(out, v[i]);
    out += (i + 1) % per_line == 0 || i + 1 == v.size() ? '\n' : ' ';
  }
}

void append_ints(std::string& out, const std::vector<int32_t>& v, size_t per_line, bool binary) {
  if (binary) {
    append_big_endian(out, v.data(), v.size());
    out += '\n';
    return;
  }
  for (size_t i = 0; i < v.size(); ++i) {
    io::append_int(out, v[i]);
    out += (i + 1) % per_line == 0 || i + 1 == v.size() ? '\n' : ' ';
  }
}

// SCALARS for one component, VECTORS for three, a FIELD block of one array otherwise
// (one block per field keeps the order of the fields when the file is read back).
void append_field(std::string& out, const Field& f, int64_t count, bool binary) {
  const std::string name = encode_name(f.name);
  if (f.components == 1) {
    out += "SCALARS " + name + " double 1\nLOOKUP_TABLE default\n";
  } else if (f.components == 3) {
    out += "VECTORS " + name + " double\n";
  } else {
    out += "FIELD FieldData 1\n" + name + " " + std::to_string(f.components) + " " + std::to_string(count) +
           " double\n";
  }
  append_doubles(out, f.values, size_t(f.components), binary);
}

}  // namespace

Mesh read_vtk(const std::string& path, ReadNotes& notes) {
  LegacyReader r(path, notes);
  return r.read();
}

// Writes the tets as the only cells (layout of version 4.2: "CELLS n size"). Triangles and
// edges are not written: as extra cells they would need values in every CELL_DATA array
// (labels and fields are per tet), which would confuse readers that take the label array
// as a per-tet material. Use Gmsh or Medit output to keep them.
void write_vtk(const std::string& path, const Mesh& mesh, const WriteOptions& options) {
  const bool binary = options.binary;
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  std::string out;
  out.reserve(size_t(nv) * (binary ? 24 : 60) + size_t(nt) * (binary ? 24 : 40) + 256);
  out += "# vtk DataFile Version 4.2\ntetcollapse " TETCOLLAPSE_VERSION "\n";
  out += binary ? "BINARY\n" : "ASCII\n";
  out += "DATASET UNSTRUCTURED_GRID\n";
  out += "POINTS " + std::to_string(nv) + " double\n";
  append_doubles(out, mesh.points, 3, binary);

  out += "CELLS " + std::to_string(nt) + " " + std::to_string(5 * nt) + "\n";
  if (binary) {
    std::vector<int32_t> list(size_t(5 * nt));
    for (int64_t t = 0; t < nt; ++t) {
      list[size_t(5 * t)] = 4;
      for (int k = 0; k < 4; ++k) list[size_t(5 * t + 1 + k)] = mesh.tets[size_t(4 * t + k)];
    }
    append_ints(out, list, 5, true);
  } else {
    for (int64_t t = 0; t < nt; ++t) {
      out += '4';
      for (int k = 0; k < 4; ++k) {
        out += ' ';
        io::append_int(out, mesh.tets[size_t(4 * t + k)]);
      }
      out += '\n';
    }
  }
  out += "CELL_TYPES " + std::to_string(nt) + "\n";
  append_ints(out, std::vector<int32_t>(size_t(nt), io::vtk::kTet), 20, binary);

  if (!mesh.tet_labels.empty() || !mesh.tet_fields.empty()) {
    out += "CELL_DATA " + std::to_string(nt) + "\n";
    for (const Labels& l : mesh.tet_labels) {
      out += "SCALARS " + encode_name(l.name) + " int 1\nLOOKUP_TABLE default\n";
      append_ints(out, l.values, 20, binary);
    }
    for (const Field& f : mesh.tet_fields) append_field(out, f, nt, binary);
  }
  if (!mesh.vertex_fields.empty()) {
    out += "POINT_DATA " + std::to_string(nv) + "\n";
    for (const Field& f : mesh.vertex_fields) append_field(out, f, nv, binary);
  }

  io::AtomicFile file(path, true);
  file.write(out.data(), out.size());
  file.commit();
}

}  // namespace tc
