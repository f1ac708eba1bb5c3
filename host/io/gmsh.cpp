// Gmsh MSH reader (2.2 and 4.1, ASCII and binary) and writer (same four variants).
//
// Why our own parser: the Gmsh API is GPL and heavyweight, meshio is Python, and we need
// one-line errors with line / byte positions, counts checked before any allocation and a
// fast path for ~1M-tet binary files. Binary data is read value by value with memcpy
// through a bounds-checked cursor; text with from_chars; nothing goes through iostreams.
//
// What is read:
//   tets (type 4)                    -> mesh.tets
//   higher-order tets (11, 29, ...)  -> their 4 corner nodes (notes.reduced_quadratic_tets)
//   triangles (2, 9, ... corners)    -> mesh.tris, tri_tags = entity (elementary) tag
//   lines (1, 8, ... end points)     -> mesh.edges, edge_tags = entity (elementary) tag
//   everything else (points, quads, hexes, prisms, pyramids) -> skipped, counted
// The entity tag is chosen for triangles and lines because it is what every Gmsh file
// has (physical groups are optional) and it names the CAD face / curve, which is what
// feature detection wants. In 2.2 files the entity tag is the second tag; an element with
// a single tag uses that one.
// Tet labels: "gmsh:physical" (2.2: first tag; 4.1: first physical tag of the volume
// entity in $Entities), present when some 3D entity has a physical group (a physical tag
// of 0 means "none"), and "gmsh:geometrical" (the entity tag).
// $NodeData / $ElementData with a string tag become vertex / tet fields; when a name
// appears in several time steps the last one in the file wins.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <unordered_map>

#include "io/io_util.hpp"
#include "tetcollapse/io.hpp"

namespace tc {
namespace {

using io::BinaryCursor;
using io::TextCursor;

// ---------------------------------------------------------------- element types

enum class Kind { Line, Tri, Tet, Other };
struct TypeInfo {
  int nodes;  // -1: unknown type
  Kind kind;
};

// Node counts of the Gmsh element types (GmshDefines.h, MSH_* names give the counts).
// High-order lines, triangles and tets list their corner nodes first.
TypeInfo type_info(int64_t type) {
  using K = Kind;
  switch (type) {
    case 1: return {2, K::Line};
    case 2: return {3, K::Tri};
    case 3: return {4, K::Other};
    case 4: return {4, K::Tet};
    case 5: return {8, K::Other};
    case 6: return {6, K::Other};
    case 7: return {5, K::Other};
    case 8: return {3, K::Line};
    case 9: return {6, K::Tri};
    case 10: return {9, K::Other};
    case 11: return {10, K::Tet};
    case 12: return {27, K::Other};
    case 13: return {18, K::Other};
    case 14: return {14, K::Other};
    case 15: return {1, K::Other};
    case 16: return {8, K::Other};
    case 17: return {20, K::Other};
    case 18: return {15, K::Other};
    case 19: return {13, K::Other};
    case 20: return {9, K::Tri};
    case 21: return {10, K::Tri};
    case 22: return {12, K::Tri};
    case 23: return {15, K::Tri};
    case 24: return {15, K::Tri};
    case 25: return {21, K::Tri};
    case 26: return {4, K::Line};
    case 27: return {5, K::Line};
    case 28: return {6, K::Line};
    case 29: return {20, K::Tet};
    case 30: return {35, K::Tet};
    case 31: return {56, K::Tet};
    case 32: return {22, K::Tet};
    case 33: return {28, K::Tet};
    case 36: return {16, K::Other};
    case 37: return {25, K::Other};
    case 38: return {36, K::Other};
    case 39: return {12, K::Other};
    case 40: return {16, K::Other};
    case 41: return {20, K::Other};
    case 42: return {28, K::Tri};
    case 43: return {36, K::Tri};
    case 44: return {45, K::Tri};
    case 45: return {55, K::Tri};
    case 46: return {66, K::Tri};
    case 47: return {49, K::Other};
    case 48: return {64, K::Other};
    case 49: return {81, K::Other};
    case 50: return {100, K::Other};
    case 51: return {121, K::Other};
    case 52: return {18, K::Tri};
    case 53: return {21, K::Tri};
    case 54: return {24, K::Tri};
    case 55: return {27, K::Tri};
    case 56: return {30, K::Tri};
    case 57: return {24, K::Other};
    case 58: return {28, K::Other};
    case 59: return {32, K::Other};
    case 60: return {36, K::Other};
    case 61: return {40, K::Other};
    case 62: return {7, K::Line};
    case 63: return {8, K::Line};
    case 64: return {9, K::Line};
    case 65: return {10, K::Line};
    case 66: return {11, K::Line};
    case 71: return {84, K::Tet};
    case 72: return {120, K::Tet};
    case 73: return {165, K::Tet};
    case 74: return {220, K::Tet};
    case 75: return {286, K::Tet};
    case 79: return {34, K::Tet};
    case 80: return {40, K::Tet};
    case 81: return {46, K::Tet};
    case 82: return {52, K::Tet};
    case 83: return {58, K::Tet};
    case 84: case 85: case 86: case 87: case 88: case 89: return {1, K::Other};
    case 90: return {40, K::Other};
    case 91: return {75, K::Other};
    case 92: return {64, K::Other};
    case 93: return {125, K::Other};
    case 94: return {216, K::Other};
    case 95: return {343, K::Other};
    case 96: return {512, K::Other};
    case 97: return {729, K::Other};
    case 98: return {1000, K::Other};
    case 99: return {32, K::Other};
    case 100: return {44, K::Other};
    case 101: return {56, K::Other};
    case 102: return {68, K::Other};
    case 103: return {80, K::Other};
    case 104: return {92, K::Other};
    case 105: return {104, K::Other};
    case 106: return {126, K::Other};
    case 107: return {196, K::Other};
    case 108: return {288, K::Other};
    case 109: return {405, K::Other};
    case 110: return {550, K::Other};
    case 111: return {24, K::Other};
    case 112: return {33, K::Other};
    case 113: return {42, K::Other};
    case 114: return {51, K::Other};
    case 115: return {60, K::Other};
    case 116: return {69, K::Other};
    case 117: return {78, K::Other};
    case 118: return {30, K::Other};
    case 119: return {55, K::Other};
    case 120: return {91, K::Other};
    case 121: return {140, K::Other};
    case 122: return {204, K::Other};
    case 123: return {285, K::Other};
    case 124: return {385, K::Other};
    case 125: return {21, K::Other};
    case 126: return {29, K::Other};
    case 127: return {37, K::Other};
    case 128: return {45, K::Other};
    case 129: return {53, K::Other};
    case 130: return {61, K::Other};
    case 131: return {69, K::Other};
    case 132: return {1, K::Other};
    case 137: return {16, K::Tet};
    case 138: return {4, K::Tri};
    case 139: return {5, K::Tet};
    case 140: return {4, K::Other};
    default: return {-1, K::Other};
  }
}

std::string type_name(int64_t type) {
  switch (type) {
    case 3: return "quad";
    case 5: return "hex";
    case 6: return "prism";
    case 7: return "pyramid";
    case 10: return "quad9";
    case 12: return "hex27";
    case 13: return "prism18";
    case 14: return "pyramid14";
    case 15: return "point";
    case 16: return "quad8";
    case 17: return "hex20";
    case 18: return "prism15";
    case 19: return "pyramid13";
    default: return "type " + std::to_string(type);
  }
}

std::string_view trim(std::string_view s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

std::string show(std::string_view s) {
  std::string r(s.substr(0, 40));
  for (char& c : r)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  if (s.size() > 40) r += "...";
  return "'" + r + "'";
}

// ---------------------------------------------------------------- value sources
//
// The section parsers are templates over the two sources below, so the same code reads
// ASCII and binary. Both report errors at "the last value read": the line for text, the
// byte offset of the value for binary. line() returns the next non-blank text line
// (section names and the text headers of binary files).

class AsciiSource {
 public:
  AsciiSource(std::string_view text, const std::string& file, size_t start) : c_(text, file), file_(file) {
    c_.set_pos(start);
  }
  void release_through(io::FileBytes* f) { c_.release_through(f); }
  int64_t integer() { return c_.next_int(); }
  int64_t size() {
    int64_t v = c_.next_int();
    if (v < 0) c_.fail("expected a count or tag >= 0, found " + std::to_string(v));
    return v;
  }
  double real() { return c_.next_double(); }
  [[noreturn]] void fail(const std::string& reason) const { c_.fail(reason); }
  [[noreturn]] void fail_line(const std::string& reason) const { throw InputError(file_, line_mark_, reason); }
  int64_t max_items(int64_t ascii_chars, int64_t /*binary_bytes*/) const { return c_.max_items(ascii_chars); }
  std::string_view line() {
    if (c_.at_end()) {
      line_mark_ = c_.line();
      return {};
    }
    line_mark_ = c_.line();
    std::string_view r = c_.rest_of_line();
    c_.skip_line();
    return trim(r);
  }
  // Skips an unknown section; false when its end marker is missing.
  bool skip_to(std::string_view end_marker) {
    size_t p = c_.text().find(end_marker, c_.pos());
    if (p == std::string_view::npos) return false;
    c_.set_pos(p);
    c_.skip_line();
    return true;
  }
  // ASCII 2.2 elements of unknown type can be skipped line by line.
  bool skip_rest_of_line() {
    c_.rest_of_line();
    return true;
  }
  static constexpr bool binary = false;

 private:
  TextCursor c_;
  std::string file_;
  int64_t line_mark_ = 1;
};

class BinarySource {
 public:
  BinarySource(std::string_view data, const std::string& file, size_t start, bool swap, int data_size)
      : c_(data, file, swap), ds_(data_size) {
    c_.set_pos(start);
  }
  void release_through(io::FileBytes* f) {
    c_.release_through(f);
    file_ = f;
  }
  // Within a block decoded in place (take): the bytes before pos are done with.
  void done_before(size_t pos) {
    if (file_) file_->done_before(pos);
  }
  int64_t integer() {
    last_ = c_.pos();
    return c_.get<int32_t>();
  }
  int64_t size() {
    last_ = c_.pos();
    if (ds_ == 4) return c_.get<uint32_t>();
    uint64_t v = c_.get<uint64_t>();
    if (v > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) fail("count or tag " + std::to_string(v) + " is out of range");
    return static_cast<int64_t>(v);
  }
  double real() {
    last_ = c_.pos();
    return c_.get<double>();
  }
  [[noreturn]] void fail(const std::string& reason) const { c_.fail_at(last_, reason); }
  [[noreturn]] void fail_line(const std::string& reason) const { c_.fail_at(last_, reason); }
  int64_t max_items(int64_t /*ascii_chars*/, int64_t binary_bytes) const {
    return static_cast<int64_t>(c_.remaining() / static_cast<size_t>(binary_bytes > 0 ? binary_bytes : 1));
  }
  std::string_view line() {
    std::string_view d = c_.data();
    size_t p = c_.pos();
    while (p < d.size() && (d[p] == ' ' || d[p] == '\t' || d[p] == '\r' || d[p] == '\n')) ++p;
    last_ = p;
    size_t e = d.find('\n', p);
    if (e == std::string_view::npos) e = d.size();
    c_.set_pos(e < d.size() ? e + 1 : e);
    return trim(d.substr(p, e - p));
  }
  bool skip_to(std::string_view end_marker) {
    std::string_view d = c_.data();
    size_t p = d.find(end_marker, c_.pos());
    if (p == std::string_view::npos) return false;
    size_t e = d.find('\n', p);
    c_.set_pos(e == std::string_view::npos ? d.size() : e + 1);
    return true;
  }
  bool skip_rest_of_line() { return false; }
  int data_size() const { return ds_; }

  // Bulk access for the hot loops: `n` bytes, bounds-checked once, then decoded in place.
  size_t pos() const { return c_.pos(); }
  const char* take(size_t n) {
    last_ = c_.pos();
    c_.need(n);
    const char* p = c_.data().data() + c_.pos();
    c_.skip(n);
    return p;
  }
  uint64_t decode_size(const char* p) const {
    if (ds_ == 4) return decode<uint32_t>(p);
    return decode<uint64_t>(p);
  }
  template <class T>
  T decode(const char* p) const {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return c_.swapping() ? BinaryCursor::byteswap_value(v) : v;
  }
  [[noreturn]] void fail_at(size_t offset, const std::string& reason) const { c_.fail_at(offset, reason); }
  BinaryCursor& cursor() { return c_; }
  static constexpr bool binary = true;

 private:
  BinaryCursor c_;
  int ds_;
  size_t last_ = 0;
  io::FileBytes* file_ = nullptr;
};

// ---------------------------------------------------------------- tag -> index maps

// Gmsh tags (nodes, elements) are positive and may be sparse. Dense lookup when the tag
// range is not much larger than the count (the usual case), sorted pairs otherwise.
class TagMap {
 public:
  // Returns the position (in `tags`) of a duplicated tag, or -1.
  int64_t build(const std::vector<int64_t>& tags) {
    dense_.clear();
    sorted_.clear();
    if (tags.empty()) return -1;
    auto [mn, mx] = std::minmax_element(tags.begin(), tags.end());
    min_ = *mn;
    const uint64_t range = static_cast<uint64_t>(*mx - *mn) + 1;
    if (range <= 4 * static_cast<uint64_t>(tags.size()) + 1024) {
      dense_.assign(static_cast<size_t>(range), -1);
      for (size_t i = 0; i < tags.size(); ++i) {
        int32_t& slot = dense_[static_cast<size_t>(tags[i] - min_)];
        if (slot >= 0) return static_cast<int64_t>(i);
        slot = static_cast<int32_t>(i);
      }
    } else {
      sorted_.resize(tags.size());
      for (size_t i = 0; i < tags.size(); ++i) sorted_[i] = {tags[i], static_cast<int32_t>(i)};
      std::sort(sorted_.begin(), sorted_.end());
      for (size_t i = 1; i < sorted_.size(); ++i)
        if (sorted_[i].first == sorted_[i - 1].first) return std::max(sorted_[i].second, sorted_[i - 1].second);
    }
    return -1;
  }
  int32_t find(int64_t tag) const {
    if (!dense_.empty()) {
      if (tag < min_ || static_cast<uint64_t>(tag - min_) >= dense_.size()) return -1;
      return dense_[static_cast<size_t>(tag - min_)];
    }
    auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair<int64_t, int32_t>(tag, INT32_MIN));
    return it != sorted_.end() && it->first == tag ? it->second : -1;
  }

 private:
  int64_t min_ = 0;
  std::vector<int32_t> dense_;
  std::vector<std::pair<int64_t, int32_t>> sorted_;
};

// ---------------------------------------------------------------- reader state

struct ReaderState {
  std::string file;
  int version = 41;  // 22 or 41
  Mesh mesh;
  ReadNotes* notes = nullptr;

  bool have_nodes = false, have_elements = false;
  TagMap nodes;

  // 4.1 $Entities: first physical tag of each volume entity (0 when none).
  std::unordered_map<int32_t, int32_t> volume_physical;
  bool any_volume_physical = false;

  std::vector<int32_t> tet_physical, tet_entity;  // per tet
  std::vector<int64_t> tet_element_tags;          // for $ElementData
  bool tet_has_physical = false, tet_has_entity = false;
  TagMap tet_lookup;
  bool tet_lookup_built = false;

  std::map<int64_t, int64_t> skipped_by_type;
  int64_t reduced_tris = 0, reduced_lines = 0;
  std::map<std::string, int> field_steps;
};

template <class Src>
int32_t to_i32(Src& s, int64_t v, const char* what) {
  if (v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max())
    s.fail(std::string(what) + " " + std::to_string(v) + " does not fit in 32 bits");
  return static_cast<int32_t>(v);
}

template <class Src>
int32_t node_index(Src& s, const ReaderState& st, int64_t tag) {
  int32_t i = st.nodes.find(tag);
  if (i < 0) s.fail("element refers to node tag " + std::to_string(tag) + ", which is not in $Nodes");
  return i;
}

template <class Src>
void read_coords(Src& s, Mesh& m, int64_t tag) {
  double x = s.real(), y = s.real(), z = s.real();
  if ((!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) && !io::lenient())
    s.fail("node " + std::to_string(tag) + " has a non-finite coordinate (NaN or infinity)");
  m.points.push_back(x);
  m.points.push_back(y);
  m.points.push_back(z);
}

template <class Src>
void finish_nodes(Src& s, ReaderState& st, const std::vector<int64_t>& tags) {
  int64_t dup = st.nodes.build(tags);
  if (dup >= 0) s.fail("node tag " + std::to_string(tags[static_cast<size_t>(dup)]) + " appears twice in $Nodes");
  st.have_nodes = true;
}

// One element of a supported kind (node indices resolved): keeps its corners, drops the rest.
void add_element(ReaderState& st, Kind kind, const int32_t* idx, int nodes, int64_t elem_tag,
                 int32_t physical, int32_t entity) {
  Mesh& m = st.mesh;
  switch (kind) {
    case Kind::Tet:
      m.tets.insert(m.tets.end(), idx, idx + 4);
      st.tet_physical.push_back(physical);
      st.tet_entity.push_back(entity);
      st.tet_element_tags.push_back(elem_tag);
      if (nodes > 4 && st.notes) ++st.notes->reduced_quadratic_tets;
      break;
    case Kind::Tri:
      m.tris.insert(m.tris.end(), idx, idx + 3);
      m.tri_tags.push_back(entity);
      if (nodes > 3) ++st.reduced_tris;
      break;
    case Kind::Line:
      m.edges.insert(m.edges.end(), idx, idx + 2);
      m.edge_tags.push_back(entity);
      if (nodes > 2) ++st.reduced_lines;
      break;
    case Kind::Other: break;
  }
}


template <class Src>
int64_t header_int(Src& s, const char* what) {
  std::string_view l = s.line();
  int64_t v = 0;
  // Only the first token counts (some writers put a comment after it).
  size_t e = l.find_first_of(" \t");
  std::string_view t = l.substr(0, e);
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || p != t.data() + t.size()) s.fail_line(std::string("expected ") + what + ", found " + show(l));
  return v;
}

// ---------------------------------------------------------------- MSH 2.2

template <class Src>
void read_nodes_22(Src& s, ReaderState& st) {
  // The count is a text line in ASCII and binary files alike.
  int64_t n = header_int(s, "the number of nodes");
  if (n < 0 || n > s.max_items(8, 28)) s.fail_line("node count " + std::to_string(n) + " is more than the rest of the file can hold");
  if (n > std::numeric_limits<int32_t>::max()) s.fail_line("more than 2^31-1 nodes are not supported");
  std::vector<int64_t> tags;
  tags.reserve(static_cast<size_t>(n));
  st.mesh.points.reserve(static_cast<size_t>(3 * n));
  for (int64_t i = 0; i < n; ++i) {
    int64_t tag = s.integer();
    if (tag <= 0) s.fail("node tag " + std::to_string(tag) + " is not positive");
    tags.push_back(tag);
    read_coords(s, st.mesh, tag);
  }
  finish_nodes(s, st, tags);
}

template <class Src>
void read_elements_22(Src& s, ReaderState& st) {
  int64_t n = header_int(s, "the number of elements");
  if (n < 0 || n > s.max_items(8, 8)) s.fail_line("element count " + std::to_string(n) + " is more than the rest of the file can hold");
  // Every node reference is resolved as it is read (so errors point at it), the extra
  // nodes of high-order and skipped elements too.
  int32_t idx[1000];
  int64_t done = 0;
  auto one = [&](int64_t type, const TypeInfo& info, int64_t ntags, bool have_elem_tag, int64_t elem_tag) {
    int64_t tag_vals[2] = {0, 0};
    for (int64_t k = 0; k < ntags; ++k) {
      int64_t v = s.integer();
      if (k < 2) tag_vals[k] = v;
    }
    (void)have_elem_tag;
    if (info.nodes < 0) {
      if (!s.skip_rest_of_line()) s.fail("unknown element type " + std::to_string(type));
      ++st.skipped_by_type[type];
      return;
    }
    for (int k = 0; k < info.nodes; ++k) idx[k] = node_index(s, st, s.integer());
    int32_t physical = ntags >= 1 ? to_i32(s, tag_vals[0], "physical tag") : 0;
    int32_t entity = ntags >= 2 ? to_i32(s, tag_vals[1], "elementary tag") : 0;
    if (info.kind == Kind::Other) {
      ++st.skipped_by_type[type];
      return;
    }
    if (info.kind == Kind::Tet) {
      if (physical != 0) st.tet_has_physical = true;
      if (ntags >= 2) st.tet_has_entity = true;
      add_element(st, info.kind, idx, info.nodes, elem_tag, physical, entity);
    } else {
      // Lines and triangles: the entity (elementary) tag; a lone tag is used as it is.
      add_element(st, info.kind, idx, info.nodes, elem_tag, physical, ntags >= 2 ? entity : physical);
    }
  };
  if constexpr (!Src::binary) {
    for (; done < n; ++done) {
      int64_t elem_tag = s.integer();
      int64_t type = s.integer();
      int64_t ntags = s.size();
      if (ntags > s.max_items(2, 4)) s.fail("tag count " + std::to_string(ntags) + " is more than the rest of the file can hold");
      one(type, type_info(type), ntags, true, elem_tag);
    }
  } else {
    // Binary 2.2: blocks of (type, count, number of tags) followed by int32 records.
    while (done < n) {
      int64_t type = s.integer();
      TypeInfo info = type_info(type);
      if (info.nodes < 0) s.fail("unknown element type " + std::to_string(type));
      int64_t count = s.integer();
      if (count <= 0 || count > n - done)
        s.fail("element block of " + std::to_string(count) + " elements does not fit the total of " + std::to_string(n));
      int64_t ntags = s.integer();
      if (ntags < 0 || ntags > 1000) s.fail("bad number of element tags " + std::to_string(ntags));
      if (count > s.max_items(0, 4 * (1 + ntags + info.nodes)))
        s.fail("element block of " + std::to_string(count) + " elements runs past the end of the file");
      for (int64_t i = 0; i < count; ++i) {
        int64_t elem_tag = s.integer();
        one(type, info, ntags, true, elem_tag);
      }
      done += count;
    }
  }
}

// ---------------------------------------------------------------- MSH 4.1

template <class Src>
void read_entities_41(Src& s, ReaderState& st) {
  int64_t counts[4];
  for (auto& c : counts) {
    c = s.size();  // checked one by one, so the error points at the bad count
    if (c > s.max_items(10, 28)) s.fail("entity count " + std::to_string(c) + " is more than the rest of the file can hold");
  }
  for (int dim = 0; dim < 4; ++dim) {
    for (int64_t i = 0; i < counts[dim]; ++i) {
      int32_t tag = to_i32(s, s.integer(), "entity tag");
      for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) s.real();
      int64_t nphys = s.size();
      if (nphys > s.max_items(2, 4)) s.fail("physical tag count " + std::to_string(nphys) + " is more than the rest of the file can hold");
      int32_t first = 0;
      for (int64_t k = 0; k < nphys; ++k) {
        int32_t p = to_i32(s, s.integer(), "physical tag");
        if (k == 0) first = p;
      }
      if (dim > 0) {
        int64_t nb = s.size();
        if (nb > s.max_items(2, 4)) s.fail("bounding entity count " + std::to_string(nb) + " is more than the rest of the file can hold");
        for (int64_t k = 0; k < nb; ++k) s.integer();
      }
      if (dim == 3) {
        st.volume_physical[tag] = first;
        if (first != 0) st.any_volume_physical = true;
      }
    }
  }
}

template <class Src>
void read_nodes_41(Src& s, ReaderState& st, int ds) {
  int64_t blocks = s.size();
  if (blocks > s.max_items(8, 12 + ds)) s.fail("node block count " + std::to_string(blocks) + " is more than the rest of the file can hold");
  int64_t n = s.size();
  if (n > s.max_items(8, 24 + ds)) s.fail("node count " + std::to_string(n) + " is more than the rest of the file can hold");
  if (n > std::numeric_limits<int32_t>::max()) s.fail("more than 2^31-1 nodes are not supported");
  s.size();  // min and max tags: computed from the tags themselves
  s.size();
  std::vector<int64_t> tags;
  tags.reserve(static_cast<size_t>(n));
  st.mesh.points.reserve(static_cast<size_t>(3 * n));
  for (int64_t b = 0; b < blocks; ++b) {
    int64_t dim = s.integer();
    s.integer();  // entity tag
    int64_t parametric = s.integer();
    int64_t count = s.size();
    if (dim < 0 || dim > 3) s.fail("node block dimension " + std::to_string(dim) + " is not 0..3");
    if (count > n - static_cast<int64_t>(tags.size()))
      s.fail("node blocks hold more than the " + std::to_string(n) + " nodes announced");
    const int extra = parametric ? static_cast<int>(dim) : 0;
    const size_t first = tags.size();
    for (int64_t i = 0; i < count; ++i) {
      int64_t tag = s.size();
      if (tag == 0) s.fail("node tag 0 is not allowed (tags start at 1)");
      tags.push_back(tag);
    }
    for (int64_t i = 0; i < count; ++i) {
      read_coords(s, st.mesh, tags[first + static_cast<size_t>(i)]);
      for (int k = 0; k < extra; ++k) s.real();
    }
  }
  if (static_cast<int64_t>(tags.size()) != n)
    s.fail("$Nodes announces " + std::to_string(n) + " nodes but its blocks hold " + std::to_string(tags.size()));
  finish_nodes(s, st, tags);
}

template <class Src>
void read_elements_41(Src& s, ReaderState& st, int ds) {
  int64_t blocks = s.size();
  if (blocks > s.max_items(8, 12 + ds)) s.fail("element block count " + std::to_string(blocks) + " is more than the rest of the file can hold");
  int64_t n = s.size();
  if (n > s.max_items(4, 2 * ds)) s.fail("element count " + std::to_string(n) + " is more than the rest of the file can hold");
  s.size();  // min and max tags
  s.size();
  int64_t total = 0;
  int32_t idx[1000];
  for (int64_t b = 0; b < blocks; ++b) {
    int64_t dim = s.integer();
    int32_t entity = to_i32(s, s.integer(), "entity tag");
    int64_t type = s.integer();
    int64_t count = s.size();
    TypeInfo info = type_info(type);
    if (info.nodes < 0) s.fail("unknown element type " + std::to_string(type));
    if (dim < 0 || dim > 3) s.fail("element block dimension " + std::to_string(dim) + " is not 0..3");
    if (count > s.max_items(2 * (1 + info.nodes), (1 + info.nodes) * ds))
      s.fail("element block of " + std::to_string(count) + " elements is more than the rest of the file can hold");
    total += count;
    if (total > n) s.fail("element blocks hold more than the " + std::to_string(n) + " elements announced");
    int32_t physical = 0;
    if (info.kind == Kind::Tet) {
      auto it = st.volume_physical.find(entity);
      if (it != st.volume_physical.end()) physical = it->second;
      st.tet_has_entity = true;
      st.mesh.tets.reserve(st.mesh.tets.size() + static_cast<size_t>(4 * count));
      st.tet_entity.reserve(st.tet_entity.size() + static_cast<size_t>(count));
      st.tet_physical.reserve(st.tet_physical.size() + static_cast<size_t>(count));
      st.tet_element_tags.reserve(st.tet_element_tags.size() + static_cast<size_t>(count));
    }
    if constexpr (Src::binary) {
      // Binary: the whole block is bounds-checked once and decoded in place (the hot loop
      // of a 1M-tet file); errors name the byte offset of the offending value.
      const size_t rec = static_cast<size_t>(1 + info.nodes) * static_cast<size_t>(ds);
      const size_t start = s.pos();
      const char* p = s.take(static_cast<size_t>(count) * rec);
      for (int64_t i = 0; i < count; ++i) {
        const char* r = p + static_cast<size_t>(i) * rec;
        s.done_before(start + static_cast<size_t>(i) * rec);
        const int64_t elem_tag = static_cast<int64_t>(s.decode_size(r));
        for (int k = 0; k < info.nodes; ++k) {
          const uint64_t tag = s.decode_size(r + static_cast<size_t>(1 + k) * ds);
          idx[k] = tag > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()) ? -1 : st.nodes.find(static_cast<int64_t>(tag));
          if (idx[k] < 0)
            s.fail_at(start + static_cast<size_t>(i) * rec + static_cast<size_t>(1 + k) * ds,
                      "element refers to node tag " + std::to_string(tag) + ", which is not in $Nodes");
        }
        if (info.kind != Kind::Other) add_element(st, info.kind, idx, info.nodes, elem_tag, physical, entity);
      }
    } else {
      for (int64_t i = 0; i < count; ++i) {
        int64_t elem_tag = s.size();
        // Every reference is resolved as it is read (errors point at it), skipped ones too.
        for (int k = 0; k < info.nodes; ++k) idx[k] = node_index(s, st, s.size());
        if (info.kind != Kind::Other) add_element(st, info.kind, idx, info.nodes, elem_tag, physical, entity);
      }
    }
    if (info.kind == Kind::Other && count > 0) st.skipped_by_type[type] += count;
  }
  if (total != n) s.fail("$Elements announces " + std::to_string(n) + " elements but its blocks hold " + std::to_string(total));
  if (st.any_volume_physical) st.tet_has_physical = true;
}

// ---------------------------------------------------------------- $NodeData / $ElementData

template <class Src>
void read_data(Src& s, ReaderState& st, bool node_data) {
  const char* section = node_data ? "$NodeData" : "$ElementData";
  if (node_data ? !st.have_nodes : !st.have_elements)
    s.fail_line(std::string(section) + " comes before " + (node_data ? "$Nodes" : "$Elements"));
  int64_t nstr = header_int(s, "the number of string tags");
  if (nstr < 0 || nstr > s.max_items(2, 2)) s.fail_line("bad number of string tags " + std::to_string(nstr));
  std::string name;
  for (int64_t i = 0; i < nstr; ++i) {
    std::string_view l = s.line();
    if (i == 0) {
      if (l.size() >= 2 && l.front() == '"' && l.back() == '"') l = l.substr(1, l.size() - 2);
      name = std::string(l);
    }
  }
  int64_t nreal = header_int(s, "the number of real tags");
  if (nreal < 0 || nreal > s.max_items(2, 2)) s.fail_line("bad number of real tags " + std::to_string(nreal));
  for (int64_t i = 0; i < nreal; ++i) s.line();
  int64_t nint = header_int(s, "the number of integer tags");
  if (nint < 3 || nint > s.max_items(2, 2))
    s.fail_line("expected at least 3 integer tags (time step, components, count), found " + std::to_string(nint));
  int64_t ints[3] = {0, 0, 0};
  for (int64_t i = 0; i < nint; ++i) {
    int64_t v = header_int(s, "an integer tag");
    if (i < 3) ints[i] = v;
  }
  const int64_t comps = ints[1], count = ints[2];
  if (comps < 1 || comps > 1000) s.fail_line("bad number of field components " + std::to_string(comps));
  if (count < 0 || count > s.max_items(2 * (1 + comps), 4 + 8 * comps))
    s.fail_line("value count " + std::to_string(count) + " is more than the rest of the file can hold");
  if (name.empty()) name = std::string(node_data ? "node_data_" : "element_data_") + std::to_string(st.field_steps.size());

  if (!node_data && !st.tet_lookup_built) {
    int64_t dup = st.tet_lookup.build(st.tet_element_tags);
    if (dup >= 0) s.fail_line("element tag " + std::to_string(st.tet_element_tags[static_cast<size_t>(dup)]) + " appears twice");
    st.tet_lookup_built = true;
  }
  const int64_t entities = node_data ? st.mesh.num_vertices() : st.mesh.num_tets();
  if (count < entities) {
    // Cannot cover every node / tet: read past the values without allocating a field
    // whose size would come from an unchecked component count.
    for (int64_t i = 0; i < count; ++i) {
      int64_t tag = s.integer();
      if (node_data && st.nodes.find(tag) < 0) s.fail("$NodeData refers to node tag " + std::to_string(tag) + ", which is not in $Nodes");
      for (int64_t k = 0; k < comps; ++k) s.real();
    }
    if (st.notes)
      st.notes->notes.push_back(std::string(section) + " '" + name + "' has " + std::to_string(count) + " values for " +
                                std::to_string(entities) + (node_data ? " nodes" : " tets") + "; skipped");
    return;
  }
  Field f;
  f.name = name;
  f.components = static_cast<int>(comps);
  f.values.assign(static_cast<size_t>(entities * comps), std::numeric_limits<double>::quiet_NaN());
  std::vector<char> seen(static_cast<size_t>(entities), 0);
  int64_t covered = 0;
  for (int64_t i = 0; i < count; ++i) {
    int64_t tag = s.integer();
    int32_t idx = node_data ? st.nodes.find(tag) : st.tet_lookup.find(tag);
    if (node_data && idx < 0) s.fail("$NodeData refers to node tag " + std::to_string(tag) + ", which is not in $Nodes");
    for (int64_t k = 0; k < comps; ++k) {
      double v = s.real();
      if (idx >= 0) f.values[static_cast<size_t>(idx * comps + k)] = v;
    }
    if (idx >= 0 && !seen[static_cast<size_t>(idx)]) {
      seen[static_cast<size_t>(idx)] = 1;
      ++covered;
    }
  }
  const int steps = ++st.field_steps[std::string(node_data ? "n:" : "e:") + name];
  if (covered != entities) {
    if (st.notes)
      st.notes->notes.push_back(std::string(section) + " '" + name + "' covers " + std::to_string(covered) + " of " +
                                std::to_string(entities) + (node_data ? " nodes" : " tets") + "; skipped");
    return;
  }
  auto& list = node_data ? st.mesh.vertex_fields : st.mesh.tet_fields;
  auto it = std::find_if(list.begin(), list.end(), [&](const Field& g) { return g.name == name; });
  if (it != list.end()) *it = std::move(f);  // a later time step replaces the earlier one
  else list.push_back(std::move(f));
  if (steps == 2 && st.notes) st.notes->notes.push_back(std::string(section) + " '" + name + "' has several time steps; kept the last");
}

// ---------------------------------------------------------------- section loop

template <class Src>
void read_sections(Src& s, ReaderState& st, int ds) {
  for (;;) {
    std::string_view l = s.line();
    if (l.empty()) break;
    if (l[0] != '$') s.fail_line("expected a section name starting with '$', found " + show(l));
    std::string name(l.substr(1));
    bool known = true;
    if (name == "Nodes") {
      if (st.have_nodes) s.fail_line("second $Nodes section");
      if (st.version == 22) read_nodes_22(s, st);
      else read_nodes_41(s, st, ds);
    } else if (name == "Elements") {
      if (!st.have_nodes) s.fail_line("$Elements comes before $Nodes");
      if (st.have_elements) s.fail_line("second $Elements section");
      if (st.version == 22) read_elements_22(s, st);
      else read_elements_41(s, st, ds);
      st.have_elements = true;
    } else if (name == "Entities" && st.version == 41) {
      read_entities_41(s, st);
    } else if (name == "NodeData" || name == "ElementData") {
      read_data(s, st, name == "NodeData");
    } else {
      known = false;
    }
    const std::string end = "$End" + name;
    if (known) {
      std::string_view e = s.line();
      if (e != end) s.fail_line("expected " + end + ", found " + (e.empty() ? std::string("the end of the file") : show(e)));
    } else {
      if (!s.skip_to(end)) s.fail_line("section $" + name + " has no " + end);
      if (name != "PhysicalNames" && name != "Comments" && st.notes)
        st.notes->notes.push_back("skipped section $" + name);
    }
  }
  if (!st.have_nodes) s.fail_line("no $Nodes section");
}

struct MshFormat {
  int version = 41;
  bool binary = false;
  int data_size = 8;
  bool swap = false;
  size_t body = 0;  // first byte after $EndMeshFormat's line
};

// $MeshFormat: "version file-type data-size", then (binary) the int 1 as endianness marker.
MshFormat read_format(std::string_view d, const std::string& file) {
  MshFormat f;
  size_t p = 0;
  int64_t line = 1;
  auto next_line = [&](std::string_view& out) {
    while (p < d.size() && (d[p] == ' ' || d[p] == '\t' || d[p] == '\r' || d[p] == '\n')) {
      if (d[p] == '\n') ++line;
      ++p;
    }
    if (p >= d.size()) return false;
    size_t e = d.find('\n', p);
    if (e == std::string_view::npos) e = d.size();
    out = trim(d.substr(p, e - p));
    p = e;  // the newline is consumed by the next call's whitespace skip
    return true;
  };
  std::string_view l;
  if (!next_line(l)) throw InputError(file, "empty file");
  if (l.rfind("$NOD", 0) == 0 || l.rfind("$PTS", 0) == 0)
    throw InputError(file, line, "Gmsh MSH version 1 is not supported (reads 2.2 and 4.1)");
  if (l != "$MeshFormat") throw InputError(file, line, "not a Gmsh file: expected $MeshFormat, found " + show(l));
  if (!next_line(l)) throw InputError(file, line, "unexpected end of file in $MeshFormat");
  std::string_view tok[3];
  {
    size_t q = 0;
    for (auto& t : tok) {
      while (q < l.size() && (l[q] == ' ' || l[q] == '\t')) ++q;
      size_t b = q;
      while (q < l.size() && l[q] != ' ' && l[q] != '\t') ++q;
      t = l.substr(b, q - b);
    }
  }
  if (tok[0].empty() || tok[1].empty()) throw InputError(file, line, "expected 'version file-type data-size', found " + show(l));
  double v = 0;
  auto [vp, vec] = std::from_chars(tok[0].data(), tok[0].data() + tok[0].size(), v);
  if (vec != std::errc() || vp != tok[0].data() + tok[0].size())
    throw InputError(file, line, "expected a format version number, found " + show(tok[0]));
  if (v >= 2.0 && v < 3.0) f.version = 22;  // 2.0 / 2.1 / 2.2 share the layout we read
  else if (tok[0] == "4.1") f.version = 41;
  else throw InputError(file, line, "unsupported Gmsh MSH version " + std::string(tok[0]) + " (reads 2.2 and 4.1)");
  if (tok[1] == "0") f.binary = false;
  else if (tok[1] == "1") f.binary = true;
  else throw InputError(file, line, "file-type must be 0 (ASCII) or 1 (binary), found " + show(tok[1]));
  if (f.binary) {
    int ds = 0;
    auto [dp, dec] = std::from_chars(tok[2].data(), tok[2].data() + tok[2].size(), ds);
    if (tok[2].empty() || dec != std::errc() || dp != tok[2].data() + tok[2].size())
      throw InputError(file, line, "expected the data-size, found " + show(tok[2]));
    if (f.version == 22 && ds != 8) throw InputError(file, line, "binary MSH 2.2 with data-size " + std::to_string(ds) + " (only 8 is supported)");
    if (f.version == 41 && ds != 4 && ds != 8) throw InputError(file, line, "binary data-size " + std::to_string(ds) + " (only 4 and 8 are supported)");
    f.data_size = ds;
    // The marker follows the newline of the format line.
    if (p < d.size()) ++p;
    if (d.size() - p < 4) throw InputError::at_byte(file, static_cast<int64_t>(p), "unexpected end of file in the binary endianness marker");
    int32_t one;
    std::memcpy(&one, d.data() + p, 4);
    if (one == 1) f.swap = false;
    else if (BinaryCursor::byteswap_value(one) == 1) f.swap = true;
    else throw InputError::at_byte(file, static_cast<int64_t>(p), "binary endianness marker is " + std::to_string(one) + ", expected 1");
    p += 4;
  }
  if (!next_line(l) || l != "$EndMeshFormat")
    throw InputError(file, line, "expected $EndMeshFormat");
  if (p < d.size()) ++p;
  f.body = p;
  return f;
}

void finish(ReaderState& st) {
  Mesh& m = st.mesh;
  if (m.num_tets() > 0) {
    if (st.tet_has_physical) m.tet_labels.push_back({"gmsh:physical", std::move(st.tet_physical)});
    if (st.tet_has_entity) m.tet_labels.push_back({"gmsh:geometrical", std::move(st.tet_entity)});
  }
  ReadNotes& n = *st.notes;
  if (n.reduced_quadratic_tets > 0)
    n.notes.push_back("kept the 4 corner nodes of " + std::to_string(n.reduced_quadratic_tets) +
                      " higher-order tets; their other nodes remain as unused vertices");
  if (st.reduced_tris > 0)
    n.notes.push_back("kept the 3 corner nodes of " + std::to_string(st.reduced_tris) + " higher-order triangles");
  if (st.reduced_lines > 0)
    n.notes.push_back("kept the 2 end nodes of " + std::to_string(st.reduced_lines) + " higher-order lines");
  if (!st.skipped_by_type.empty()) {
    std::string s;
    int64_t total = 0;
    for (auto [type, count] : st.skipped_by_type) {
      s += (s.empty() ? "" : ", ") + std::to_string(count) + " " + type_name(type);
      total += count;
    }
    n.skipped_elements += total;
    n.notes.push_back("skipped " + std::to_string(total) + " elements that are not tets, triangles or lines: " + s);
  }
}

}  // namespace

Mesh read_gmsh(const std::string& path, ReadNotes& notes) {
  io::FileBytes file(path);
  const std::string_view data = file.view();
  const MshFormat f = read_format(data, path);
  ReaderState st;
  st.file = path;
  st.version = f.version;
  st.notes = &notes;
  if (f.binary) {
    BinarySource s(data, path, f.body, f.swap, f.data_size);
    s.release_through(&file);
    read_sections(s, st, f.data_size);
  } else {
    AsciiSource s(data, path, f.body);
    s.release_through(&file);
    read_sections(s, st, 8);
  }
  finish(st);
  return std::move(st.mesh);
}

// ================================================================ writer

namespace {

struct Box {
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                  -std::numeric_limits<double>::infinity()};
  void add(const double* p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  void fix() {
    if (lo[0] > hi[0])
      for (int k = 0; k < 3; ++k) lo[k] = hi[k] = 0;
  }
};

struct Entity {
  int32_t tag;
  int32_t physical;  // 0: none
  Box box;
};

// Entities of one dimension and the entity index of each element.
struct EntitySet {
  std::vector<Entity> list;
  std::vector<int32_t> of_element;  // index into list
};

// Output buffer: text or raw bytes, flushed to the file in large pieces.
class Out {
 public:
  Out(io::AtomicFile& f, bool binary, bool swap = false) : f_(f), binary_(binary), swap_(swap) { buf_.reserve(1 << 22); }
  void text(std::string_view s) { buf_.append(s); }
  void num(int64_t v) { io::append_int(buf_, v); }
  void dbl(double v) { io::append_double(buf_, v); }
  void ch(char c) { buf_.push_back(c); }
  template <class T>
  void raw(T v) {
    if (swap_) v = BinaryCursor::byteswap_value(v);
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    buf_.append(b, sizeof(T));
  }
  template <class T>
  void raw_array(const T* p, size_t n) {
    if (swap_) {
      for (size_t i = 0; i < n; ++i) raw(p[i]);
    } else {
      buf_.append(reinterpret_cast<const char*>(p), n * sizeof(T));
    }
    maybe_flush();
  }
  // A "size_t" of MSH 4.1 (data-size 8).
  void size(uint64_t v) { raw<uint64_t>(v); }
  void maybe_flush() {
    if (buf_.size() > (16u << 20)) flush();
  }
  void flush() {
    f_.write(buf_.data(), buf_.size());
    buf_.clear();
  }
  bool binary() const { return binary_; }

 private:
  io::AtomicFile& f_;
  std::string buf_;
  bool binary_, swap_;
};

void check_mesh(const std::string& path, const Mesh& m) {
  auto bad = [&](const std::string& why) { throw OutputError(path + ": cannot write the mesh: " + why); };
  if (m.points.size() % 3 || m.tets.size() % 4 || m.tris.size() % 3 || m.edges.size() % 2) bad("array sizes are not multiples of 3/4/3/2");
  const int64_t nv = m.num_vertices();
  auto in_range = [&](const std::vector<int32_t>& a, const char* what) {
    for (int32_t v : a)
      if (v < 0 || v >= nv) bad(std::string(what) + " refer to a vertex outside 0.." + std::to_string(nv - 1));
  };
  in_range(m.tets, "tets");
  in_range(m.tris, "triangles");
  in_range(m.edges, "edges");
  if (m.tri_tags.size() != m.tris.size() / 3) bad("tri_tags size does not match the triangles");
  if (m.edge_tags.size() != m.edges.size() / 2) bad("edge_tags size does not match the edges");
  for (const auto& l : m.tet_labels)
    if (static_cast<int64_t>(l.values.size()) != m.num_tets()) bad("label '" + l.name + "' size does not match the tets");
  for (const auto& f : m.vertex_fields)
    if (f.components < 1 || static_cast<int64_t>(f.values.size()) != nv * f.components) bad("vertex field '" + f.name + "' has the wrong size");
  for (const auto& f : m.tet_fields)
    if (f.components < 1 || static_cast<int64_t>(f.values.size()) != m.num_tets() * f.components)
      bad("tet field '" + f.name + "' has the wrong size");
}

// Volume entities: one per distinct (geometrical, physical) pair. The geometrical tag is
// kept as the entity tag when it is positive and not already taken by another pair (a tag
// seen with two physical groups); otherwise a fresh tag above all others is used. Without
// gmsh labels the primary label array (e.g. medit:ref, mat_id) becomes both, so materials
// survive a conversion; without any label every tet is in volume 1.
EntitySet volume_entities(const Mesh& m) {
  const Labels* phys = m.find_labels("gmsh:physical");
  const Labels* geo = m.find_labels("gmsh:geometrical");
  if (!phys && !geo && !m.tet_labels.empty()) phys = &m.tet_labels[0];
  if (!geo) geo = phys;
  const size_t nt = static_cast<size_t>(m.num_tets());
  EntitySet es;
  es.of_element.resize(nt);
  std::map<std::pair<int32_t, int32_t>, int32_t> index;  // (geo, phys) -> entity index
  std::unordered_map<int32_t, int32_t> taken;            // entity tag -> entity index
  int32_t max_tag = 0;
  for (size_t t = 0; t < nt; ++t) {
    int32_t g = geo ? geo->values[t] : 1;
    int32_t p = phys ? phys->values[t] : 0;
    auto [it, fresh] = index.try_emplace({g, p}, static_cast<int32_t>(es.list.size()));
    if (fresh) {
      es.list.push_back({0, p, {}});
      if (g > 0 && !taken.count(g)) {
        taken[g] = it->second;
        es.list.back().tag = g;
        max_tag = std::max(max_tag, g);
      }
    }
    es.of_element[t] = it->second;
  }
  for (auto& e : es.list)
    if (e.tag == 0) e.tag = ++max_tag;
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) es.list[es.of_element[t]].box.add(&m.points[3 * static_cast<size_t>(m.tets[4 * t + k])]);
  for (auto& e : es.list) e.box.fix();
  return es;
}

// Surface / curve entities: one per distinct tag, the tag as it is.
EntitySet tag_entities(const Mesh& m, const std::vector<int32_t>& elems, const std::vector<int32_t>& tags, int per) {
  EntitySet es;
  std::unordered_map<int32_t, int32_t> index;
  es.of_element.resize(tags.size());
  for (size_t i = 0; i < tags.size(); ++i) {
    auto [it, fresh] = index.try_emplace(tags[i], static_cast<int32_t>(es.list.size()));
    if (fresh) es.list.push_back({tags[i], 0, {}});
    es.of_element[i] = it->second;
    for (int k = 0; k < per; ++k) es.list[it->second].box.add(&m.points[3 * static_cast<size_t>(elems[per * i + k])]);
  }
  for (auto& e : es.list) e.box.fix();
  return es;
}

std::string quoted_name(const std::string& name) {
  std::string s = "\"";
  for (char c : name) s += (c == '"' ? '\'' : (c == '\n' || c == '\r') ? ' ' : c);
  return s + "\"";
}

void write_data(Out& o, const Field& f, bool node_data, int64_t count) {
  const char* sec = node_data ? "NodeData" : "ElementData";
  o.text(std::string("$") + sec + "\n1\n" + quoted_name(f.name) + "\n1\n0\n3\n0\n");
  o.num(f.components);
  o.ch('\n');
  o.num(count);
  o.ch('\n');
  const size_t c = static_cast<size_t>(f.components);
  // Tags: vertices are nodes 1..n; tets are elements 1..n (written first).
  for (int64_t i = 0; i < count; ++i) {
    const double* v = &f.values[static_cast<size_t>(i) * c];
    if (o.binary()) {
      o.raw<int32_t>(static_cast<int32_t>(i + 1));
      for (size_t k = 0; k < c; ++k) o.raw<double>(v[k]);
    } else {
      o.num(i + 1);
      for (size_t k = 0; k < c; ++k) {
        o.ch(' ');
        o.dbl(v[k]);
      }
      o.ch('\n');
    }
    if ((i & 0xffff) == 0) o.maybe_flush();
  }
  if (o.binary()) o.ch('\n');
  o.text(std::string("$End") + sec + "\n");
}

// Runs of consecutive elements in the same entity become one element block each, so the
// element order (and with it every per-tet array) is kept exactly.
template <class F>
void for_each_run(const std::vector<int32_t>& of_element, F&& f) {
  size_t b = 0;
  while (b < of_element.size()) {
    size_t e = b + 1;
    while (e < of_element.size() && of_element[e] == of_element[b]) ++e;
    f(b, e);
    b = e;
  }
}

void write_41(Out& o, const Mesh& m) {
  const bool bin = o.binary();
  const int64_t nv = m.num_vertices(), nt = m.num_tets(), ntri = m.num_tris(), ned = static_cast<int64_t>(m.edge_tags.size());
  EntitySet vol = volume_entities(m);
  EntitySet sur = tag_entities(m, m.tris, m.tri_tags, 3);
  EntitySet cur = tag_entities(m, m.edges, m.edge_tags, 2);
  // When the volumes have physical groups, surfaces and curves get one too (their own
  // tag): Gmsh saves only elements in physical groups in that case, and meshio 5.0
  // needs every element block to have a physical tag or none to have one.
  const bool physical = std::any_of(vol.list.begin(), vol.list.end(), [](const Entity& e) { return e.physical != 0; });
  if (physical)
    for (EntitySet* es : {&sur, &cur})
      for (Entity& e : es->list) e.physical = e.tag;
  if (vol.list.empty() && nv > 0) {  // nodes need an entity to live on
    Entity e{1, 0, {}};
    for (int64_t v = 0; v < nv; ++v) e.box.add(&m.points[3 * v]);
    vol.list.push_back(e);
  }

  o.text(bin ? "$MeshFormat\n4.1 1 8\n" : "$MeshFormat\n4.1 0 8\n");
  if (bin) {
    o.raw<int32_t>(1);
    o.ch('\n');
  }
  o.text("$EndMeshFormat\n$Entities\n");
  const EntitySet* sets[3] = {&cur, &sur, &vol};
  if (bin) {
    o.size(0);
    for (auto* s : sets) o.size(s->list.size());
    for (auto* s : sets)
      for (const Entity& e : s->list) {
        o.raw<int32_t>(e.tag);
        for (int k = 0; k < 3; ++k) o.raw<double>(e.box.lo[k]);
        for (int k = 0; k < 3; ++k) o.raw<double>(e.box.hi[k]);
        o.size(e.physical ? 1 : 0);
        if (e.physical) o.raw<int32_t>(e.physical);
        o.size(0);  // no bounding entities
      }
    o.ch('\n');
  } else {
    o.text("0 ");
    o.num(static_cast<int64_t>(cur.list.size()));
    o.ch(' ');
    o.num(static_cast<int64_t>(sur.list.size()));
    o.ch(' ');
    o.num(static_cast<int64_t>(vol.list.size()));
    o.ch('\n');
    for (auto* s : sets)
      for (const Entity& e : s->list) {
        o.num(e.tag);
        for (int k = 0; k < 3; ++k) o.ch(' '), o.dbl(e.box.lo[k]);
        for (int k = 0; k < 3; ++k) o.ch(' '), o.dbl(e.box.hi[k]);
        if (e.physical) o.text(" 1 "), o.num(e.physical);
        else o.text(" 0");
        o.text(" 0\n");
      }
  }
  o.text("$EndEntities\n$Nodes\n");
  const int64_t nblocks = nv > 0 ? 1 : 0;
  const int32_t node_entity = vol.list.empty() ? 1 : vol.list[0].tag;
  if (bin) {
    o.size(nblocks), o.size(nv), o.size(nv > 0 ? 1 : 0), o.size(nv);
    if (nv > 0) {
      o.raw<int32_t>(3), o.raw<int32_t>(node_entity), o.raw<int32_t>(0), o.size(nv);
      std::vector<uint64_t> tags(static_cast<size_t>(nv));
      for (int64_t v = 0; v < nv; ++v) tags[v] = static_cast<uint64_t>(v + 1);
      o.raw_array(tags.data(), tags.size());
      o.raw_array(m.points.data(), m.points.size());
    }
    o.ch('\n');
  } else {
    o.num(nblocks), o.ch(' '), o.num(nv), o.ch(' '), o.num(nv > 0 ? 1 : 0), o.ch(' '), o.num(nv), o.ch('\n');
    if (nv > 0) {
      o.text("3 "), o.num(node_entity), o.text(" 0 "), o.num(nv), o.ch('\n');
      for (int64_t v = 0; v < nv; ++v) o.num(v + 1), o.ch('\n');
      for (int64_t v = 0; v < nv; ++v) {
        o.dbl(m.points[3 * v]), o.ch(' '), o.dbl(m.points[3 * v + 1]), o.ch(' '), o.dbl(m.points[3 * v + 2]), o.ch('\n');
        if ((v & 0xffff) == 0) o.maybe_flush();
      }
    }
  }
  o.text("$EndNodes\n$Elements\n");
  // Element tags: tets 1..nt, then triangles, then lines.
  struct Group {
    const EntitySet* es;
    const std::vector<int32_t>* conn;
    int per, dim, type;
    int64_t first_tag;
  };
  const Group groups[3] = {{&vol, &m.tets, 4, 3, 4, 1}, {&sur, &m.tris, 3, 2, 2, 1 + nt}, {&cur, &m.edges, 2, 1, 1, 1 + nt + ntri}};
  int64_t nblk = 0;
  for (const Group& g : groups) for_each_run(g.es->of_element, [&](size_t, size_t) { ++nblk; });
  const int64_t ne = nt + ntri + ned;
  if (bin) {
    o.size(nblk), o.size(ne), o.size(ne > 0 ? 1 : 0), o.size(ne);
  } else {
    o.num(nblk), o.ch(' '), o.num(ne), o.ch(' '), o.num(ne > 0 ? 1 : 0), o.ch(' '), o.num(ne), o.ch('\n');
  }
  std::vector<uint64_t> rec;
  for (const Group& g : groups) {
    for_each_run(g.es->of_element, [&](size_t b, size_t e) {
      const int32_t tag = g.es->list[g.es->of_element[b]].tag;
      const int64_t count = static_cast<int64_t>(e - b);
      const int32_t* conn = g.conn->data();
      if (bin) {
        o.raw<int32_t>(g.dim), o.raw<int32_t>(tag), o.raw<int32_t>(g.type), o.size(count);
        rec.resize(static_cast<size_t>(count) * (1 + g.per));
        uint64_t* r = rec.data();
        for (size_t i = b; i < e; ++i) {
          *r++ = static_cast<uint64_t>(g.first_tag + static_cast<int64_t>(i));
          for (int k = 0; k < g.per; ++k) *r++ = static_cast<uint64_t>(conn[g.per * i + k]) + 1;
        }
        o.raw_array(rec.data(), rec.size());
      } else {
        o.num(g.dim), o.ch(' '), o.num(tag), o.ch(' '), o.num(g.type), o.ch(' '), o.num(count), o.ch('\n');
        for (size_t i = b; i < e; ++i) {
          o.num(g.first_tag + static_cast<int64_t>(i));
          for (int k = 0; k < g.per; ++k) o.ch(' '), o.num(int64_t(conn[g.per * i + k]) + 1);
          o.ch('\n');
          if ((i & 0xffff) == 0) o.maybe_flush();
        }
      }
    });
  }
  if (bin) o.ch('\n');
  o.text("$EndElements\n");
}

void write_22(Out& o, const Mesh& m) {
  const bool bin = o.binary();
  const int64_t nv = m.num_vertices(), nt = m.num_tets(), ntri = m.num_tris(), ned = static_cast<int64_t>(m.edge_tags.size());
  EntitySet vol = volume_entities(m);
  o.text(bin ? "$MeshFormat\n2.2 1 8\n" : "$MeshFormat\n2.2 0 8\n");
  if (bin) {
    o.raw<int32_t>(1);
    o.ch('\n');
  }
  o.text("$EndMeshFormat\n$Nodes\n");
  o.num(nv), o.ch('\n');
  for (int64_t v = 0; v < nv; ++v) {
    if (bin) {
      o.raw<int32_t>(static_cast<int32_t>(v + 1));
      o.raw<double>(m.points[3 * v]), o.raw<double>(m.points[3 * v + 1]), o.raw<double>(m.points[3 * v + 2]);
    } else {
      o.num(v + 1), o.ch(' '), o.dbl(m.points[3 * v]), o.ch(' '), o.dbl(m.points[3 * v + 1]), o.ch(' '), o.dbl(m.points[3 * v + 2]), o.ch('\n');
    }
    if ((v & 0xffff) == 0) o.maybe_flush();
  }
  if (bin) o.ch('\n');
  o.text("$EndNodes\n$Elements\n");
  o.num(nt + ntri + ned), o.ch('\n');
  // Each element has 2 tags: physical (0 = none) and elementary (entity).
  auto group = [&](int type, int per, int64_t count, int64_t first_tag, const std::vector<int32_t>& conn, auto&& tags_of) {
    if (count == 0) return;
    if (bin) o.raw<int32_t>(type), o.raw<int32_t>(static_cast<int32_t>(count)), o.raw<int32_t>(2);
    std::vector<int32_t> rec;
    if (bin) rec.reserve(static_cast<size_t>(std::min<int64_t>(count, 1 << 16)) * (3 + per));
    for (int64_t i = 0; i < count; ++i) {
      auto [phys, ent] = tags_of(i);
      if (bin) {
        rec.push_back(static_cast<int32_t>(first_tag + i));
        rec.push_back(phys);
        rec.push_back(ent);
        for (int k = 0; k < per; ++k) rec.push_back(conn[per * i + k] + 1);
        if (rec.size() >= (size_t(1) << 16) * (3 + per)) {
          o.raw_array(rec.data(), rec.size());
          rec.clear();
        }
      } else {
        o.num(first_tag + i), o.ch(' '), o.num(type), o.text(" 2 "), o.num(phys), o.ch(' '), o.num(ent);
        for (int k = 0; k < per; ++k) o.ch(' '), o.num(int64_t(conn[per * i + k]) + 1);
        o.ch('\n');
        if ((i & 0xffff) == 0) o.maybe_flush();
      }
    }
    if (bin) o.raw_array(rec.data(), rec.size());
  };
  group(4, 4, nt, 1, m.tets, [&](int64_t i) {
    const Entity& e = vol.list[vol.of_element[i]];
    return std::pair<int32_t, int32_t>(e.physical, e.tag);
  });
  group(2, 3, ntri, 1 + nt, m.tris, [&](int64_t i) { return std::pair<int32_t, int32_t>(0, m.tri_tags[i]); });
  group(1, 2, ned, 1 + nt + ntri, m.edges, [&](int64_t i) { return std::pair<int32_t, int32_t>(0, m.edge_tags[i]); });
  if (bin) o.ch('\n');
  o.text("$EndElements\n");
}

}  // namespace

void write_gmsh(const std::string& path, const Mesh& mesh, const WriteOptions& options) {
  if (options.gmsh_version != 22 && options.gmsh_version != 41)
    throw OutputError(path + ": unsupported Gmsh version " + std::to_string(options.gmsh_version) + " (write 22 or 41)");
  check_mesh(path, mesh);
  const int64_t elements = mesh.num_tets() + mesh.num_tris() + static_cast<int64_t>(mesh.edge_tags.size());
  if (options.gmsh_version == 22 && (mesh.num_vertices() >= std::numeric_limits<int32_t>::max() ||
                                     elements >= std::numeric_limits<int32_t>::max()))
    throw OutputError(path + ": too many nodes or elements for MSH 2.2 (32-bit tags)");
  io::AtomicFile file(path, true);
  Out o(file, options.binary);
  if (options.gmsh_version == 41) write_41(o, mesh);
  else write_22(o, mesh);
  for (const Field& f : mesh.vertex_fields) write_data(o, f, true, mesh.num_vertices());
  for (const Field& f : mesh.tet_fields) write_data(o, f, false, mesh.num_tets());
  o.flush();
  file.commit();
}

}  // namespace tc
