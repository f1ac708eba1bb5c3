// Medit / libMeshb meshes: .mesh (ASCII), .meshb (binary), and their solution files
// .sol / .solb.
//
// Layout (as written by libMeshb 7, the reference implementation):
//   ASCII:  "MeshVersionFormatted V", "Dimension 3", then sections "Keyword  count  lines...",
//           closed by "End". Indices are one-based; every element line ends with a reference.
//   Binary: int32 1 (byte-order mark; 16777216 when the writer had the other byte order),
//           int32 version, then keywords: int32 code, position of the next keyword (int32 for
//           versions 1-2, int64 for 3-4; 0 after End), the line count (int32, int64 in
//           version 4), and the lines. Reals are float in version 1, double from version 2;
//           integers int32 up to version 3, int64 in version 4.
//   Solutions: "SolAtVertices n  ntypes type1 type2 ..." then n lines of the concatenated
//           values; type 1 = scalar, 2 = vector (3), 3 = symmetric tensor (6), 4 = full (9).
//
// What we keep: Vertices (refs dropped, noted when non-zero), Tetrahedra (ref -> label
// "medit:ref"), TetrahedraP2 (kept as their 4 corners), Triangles (ref -> tri_tags),
// Edges (ref -> edge_tags); from the .sol/.solb beside the mesh, SolAtVertices ->
// vertex fields and SolAtTetrahedra -> tet fields, named "sol0", "sol1", ... in file
// order (numbered over both keywords). Other volume elements (Prisms, Hexahedra,
// Pyramids, HexahedraQ2) are counted in ReadNotes::skipped_elements; feature keywords
// (Corners, Ridges, Required*, Normals, Tangents, ...) are read, ignored and noted.
// Keywords are matched without regard to case. An unknown keyword in an ASCII file is
// skipped up to the next word that starts with a letter (noted); in a binary file it is
// skipped through its next-keyword position.
//
// Writing: .mesh is ASCII ("MeshVersionFormatted 2", shortest round-trip doubles), .meshb
// binary version 2 (double, int32; version 3 when the file would pass 2 GiB). The tet
// reference is the "medit:ref" label, else the first label array, else 0. Vertex fields go
// to FILE.sol (FILE.solb beside a .meshb) as SolAtVertices, tet fields as SolAtTetrahedra:
// 1, 3, 6 and 9 components are written as types 1, 2, 3, 4; a field with another number
// of components is written as that many scalar solutions. Both files are committed
// together. A mesh without fields removes a stale FILE.sol(b) beside the target, which
// would otherwise no longer match the new mesh.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/comments.hpp"
#include "io/io_util.hpp"
#include "tetcollapse/io.hpp"

namespace tc {
namespace {

using io::BinaryCursor;
using io::TextCursor;

// Keyword codes of libMeshb (GmfKwdFmt order).
enum Code : int {
  kDimension = 3, kVertices = 4, kEdges = 5, kTriangles = 6, kQuadrilaterals = 7, kTetrahedra = 8,
  kPrisms = 9, kHexahedra = 10, kTetrahedraP2 = 30, kHexahedraQ2 = 33, kPyramids = 49, kEnd = 54,
  kSolAtVertices = 62, kSolAtTetrahedra = 66,
};

// What the ASCII reader must know to read or skip a section: `ints` and `reals` per line
// (reals already multiplied out for dimension 3), whether a count precedes the lines, and
// whether it is a solution keyword (types follow the count). Volume element keywords that
// are not tetrahedra are marked so they count as skipped elements.
struct Keyword {
  const char* name;
  int code;
  int ints;
  int reals;
  bool counted;
  bool solution;
  bool volume;
};

constexpr Keyword kKeywords[] = {
    {"MeshVersionFormatted", 1, 1, 0, false, false, false},
    {"Dimension", kDimension, 1, 0, false, false, false},
    {"Vertices", kVertices, 1, 3, true, false, false},
    {"Edges", kEdges, 3, 0, true, false, false},
    {"Triangles", kTriangles, 4, 0, true, false, false},
    {"Quadrilaterals", kQuadrilaterals, 5, 0, true, false, false},
    {"Tetrahedra", kTetrahedra, 5, 0, true, false, false},
    {"Prisms", kPrisms, 7, 0, true, false, true},
    {"Hexahedra", kHexahedra, 9, 0, true, false, true},
    {"Corners", 13, 1, 0, true, false, false},
    {"Ridges", 14, 1, 0, true, false, false},
    {"RequiredVertices", 15, 1, 0, true, false, false},
    {"RequiredEdges", 16, 1, 0, true, false, false},
    {"RequiredTriangles", 17, 1, 0, true, false, false},
    {"RequiredQuadrilaterals", 18, 1, 0, true, false, false},
    {"TangentAtEdgeVertices", 19, 3, 0, true, false, false},
    {"NormalAtVertices", 20, 2, 0, true, false, false},
    {"NormalAtTriangleVertices", 21, 3, 0, true, false, false},
    {"NormalAtQuadrilateralVertices", 22, 4, 0, true, false, false},
    {"AngleOfCornerBound", 23, 0, 1, false, false, false},
    {"TrianglesP2", 24, 7, 0, true, false, false},
    {"EdgesP2", 25, 4, 0, true, false, false},
    {"QuadrilateralsQ2", 27, 10, 0, true, false, false},
    {"SubDomainFromGeom", 29, 3, 0, true, false, false},
    {"TetrahedraP2", kTetrahedraP2, 11, 0, true, false, false},
    {"HexahedraQ2", kHexahedraQ2, 28, 0, true, false, true},
    {"VerticesOnGeometricVertices", 40, 2, 0, true, false, false},
    {"VerticesOnGeometricEdges", 41, 2, 2, true, false, false},
    {"VerticesOnGeometricTriangles", 42, 2, 3, true, false, false},
    {"VerticesOnGeometricQuadrilaterals", 43, 2, 3, true, false, false},
    {"EdgesOnGeometricEdges", 44, 2, 0, true, false, false},
    {"Pyramids", kPyramids, 6, 0, true, false, true},
    {"BoundingBox", 50, 0, 6, false, false, false},
    {"End", kEnd, 0, 0, false, false, false},
    {"TrianglesOnGeometricTriangles", 55, 2, 0, true, false, false},
    {"TrianglesOnGeometricQuadrilaterals", 56, 2, 0, true, false, false},
    {"QuadrilateralsOnGeometricTriangles", 57, 2, 0, true, false, false},
    {"QuadrilateralsOnGeometricQuadrilaterals", 58, 2, 0, true, false, false},
    {"Tangents", 59, 0, 3, true, false, false},
    {"Normals", 60, 0, 3, true, false, false},
    {"TangentAtVertices", 61, 2, 0, true, false, false},
    {"SolAtVertices", kSolAtVertices, 0, 0, true, true, false},
    {"SolAtEdges", 63, 0, 0, true, true, false},
    {"SolAtTriangles", 64, 0, 0, true, true, false},
    {"SolAtQuadrilaterals", 65, 0, 0, true, true, false},
    {"SolAtTetrahedra", kSolAtTetrahedra, 0, 0, true, true, false},
    {"SolAtPrisms", 67, 0, 0, true, true, false},
    {"SolAtHexahedra", 68, 0, 0, true, true, false},
};

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

const Keyword* find_keyword(std::string_view name) {
  for (const Keyword& k : kKeywords)
    if (iequals(k.name, name)) return &k;
  return nullptr;
}

const Keyword* find_keyword(int code) {
  for (const Keyword& k : kKeywords)
    if (k.code == code) return &k;
  return nullptr;
}

std::string plural(int64_t n, const char* what) { return std::to_string(n) + " " + what; }

// Components of a Medit solution type in 3D; 0 when the type is unknown.
int sol_components(int64_t type) {
  switch (type) {
    case 1: return 1;
    case 2: return 3;
    case 3: return 6;
    case 4: return 9;
    default: return 0;
  }
}

// Everything a reader collects before it can check the cross-references.
struct Pending {
  int64_t max_index = 0;   // largest one-based vertex index seen before Vertices was read
  int64_t line = -1;       // where (ASCII line or binary offset)
  std::string keyword;
};

std::string out_of_range(int64_t v, int64_t nv) {
  return "vertex index " + std::to_string(v) + " is out of range (the file has " + plural(nv, "vertices") + ")";
}

// ------------------------------------------------------------------------------ ASCII

class AsciiReader {
 public:
  AsciiReader(TextCursor& c, ReadNotes& notes) : c_(c), notes_(notes) {}

  Mesh read() {
    Mesh m;
    bool have_vertices = false;
    int64_t nonzero_vertex_refs = 0;
    while (!c_.at_end()) {
      std::string_view word = c_.next_token();
      const Keyword* k = find_keyword(word);
      if (!k) {
        skip_unknown(word);
        continue;
      }
      const int64_t line = c_.line();
      switch (k->code) {
        case 1: {
          int64_t v = c_.next_int();
          if (v < 1 || v > 4) c_.fail("MeshVersionFormatted " + std::to_string(v) + " is not 1 to 4");
          break;
        }
        case kDimension: {
          int64_t d = c_.next_int();
          if (d != 3) c_.fail("Dimension " + std::to_string(d) + ": only 3D meshes are supported");
          break;
        }
        case kVertices: {
          if (have_vertices) c_.fail("a second Vertices section");
          have_vertices = true;
          // Shortest vertex line: "0 0 0 0\n".
          int64_t n = c_.next_count("vertex count", c_.max_items(8));
          if (n > std::numeric_limits<int32_t>::max()) c_.fail("more vertices than 32-bit indices can address");
          m.points.resize(static_cast<size_t>(3 * n));
          for (int64_t i = 0; i < n; ++i) {
            for (int d = 0; d < 3; ++d) m.points[3 * i + d] = c_.next_finite_double("vertex coordinate");
            if (next_int32("vertex reference") != 0) ++nonzero_vertex_refs;
          }
          nv_ = n;
          break;
        }
        case kTetrahedra:
        case kTetrahedraP2: {
          const int per = k->code == kTetrahedra ? 4 : 10;
          std::vector<int32_t> refs;
          int64_t n = read_elements(*k, per, 4, m.tets, &refs);
          if (k->code == kTetrahedraP2) notes_.reduced_quadratic_tets += n;
          append_refs(m, refs);
          break;
        }
        case kTriangles: read_elements(*k, 3, 3, m.tris, &m.tri_tags); break;
        case kEdges: read_elements(*k, 2, 2, m.edges, &m.edge_tags); break;
        default: skip_section(*k, line); break;
      }
      if (k->code == kEnd) break;
    }
    if (!have_vertices) c_.fail("no Vertices section in the file");
    for (const Pending& p : pending_)
      if (p.max_index > nv_)
        throw InputError(c_.file(), p.line, p.keyword + ": " + out_of_range(p.max_index, nv_));
    if (nonzero_vertex_refs > 0)
      notes_.notes.push_back(plural(nonzero_vertex_refs, "vertices") + " have a non-zero Medit reference (dropped)");
    return m;
  }

 private:
  int32_t next_int32(const char* what) {
    int64_t v = c_.next_int();
    if (v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max())
      c_.fail(std::string(what) + " " + std::to_string(v) + " does not fit in 32 bits");
    return static_cast<int32_t>(v);
  }

  // Reads `count` lines of `per` one-based vertex indices and a reference; keeps the
  // first `keep` indices (zero-based) in conn and the reference in refs.
  int64_t read_elements(const Keyword& k, int per, int keep, std::vector<int32_t>& conn,
                        std::vector<int32_t>* refs) {
    const int64_t section_line = c_.line();
    // Shortest line: one digit and a space per index, and the reference.
    int64_t n = c_.next_count((std::string(k.name) + " count").c_str(), c_.max_items(2 * (per + 1)));
    const size_t base = conn.size();
    conn.resize(base + static_cast<size_t>(n * keep));
    if (refs) refs->reserve(refs->size() + static_cast<size_t>(n));
    int64_t max_seen = 0;
    for (int64_t i = 0; i < n; ++i) {
      for (int j = 0; j < per; ++j) {
        int64_t v = c_.next_int();
        const bool keep_bad = io::lenient() && k.code == kTetrahedra;  // the checker reports it
        if (v == 0 && !keep_bad) c_.fail("index 0 where Medit indices are one-based (" + std::string(k.name) + ")");
        if (v < 0 && !keep_bad) c_.fail("negative vertex index " + std::to_string(v) + " (" + std::string(k.name) + ")");
        if (nv_ >= 0 && v > nv_ && !keep_bad) c_.fail(std::string(k.name) + ": " + out_of_range(v, nv_));
        if (v > std::numeric_limits<int32_t>::max() || v < std::numeric_limits<int32_t>::min() + 1)
          c_.fail(out_of_range(v, std::max<int64_t>(nv_, 0)));
        max_seen = std::max(max_seen, v);
        if (j < keep) conn[base + static_cast<size_t>(i * keep + j)] = static_cast<int32_t>(v - 1);
      }
      int32_t ref = next_int32("reference");
      if (refs) refs->push_back(ref);
    }
    if (nv_ < 0 && n > 0 && !(io::lenient() && k.code == kTetrahedra)) pending_.push_back({max_seen, section_line, k.name});
    return n;
  }

  void append_refs(Mesh& m, const std::vector<int32_t>& refs) {
    if (m.tet_labels.empty()) m.tet_labels.push_back({"medit:ref", {}});
    auto& v = m.tet_labels[0].values;
    v.insert(v.end(), refs.begin(), refs.end());
  }

  void skip_section(const Keyword& k, int64_t line) {
    if (k.code == kEnd || k.code == 1) return;
    int64_t n = 1;
    int64_t per = k.ints + k.reals;
    if (k.counted) n = c_.next_count((std::string(k.name) + " count").c_str(), c_.max_items(2));
    if (k.solution) {
      int64_t ntypes = c_.next_count("number of solution types", 64);
      per = 0;
      for (int64_t t = 0; t < ntypes; ++t) {
        int64_t type = c_.next_int();
        int comps = sol_components(type);
        if (comps == 0) c_.fail("unknown solution type " + std::to_string(type));
        per += comps;
      }
    }
    if (per > 0 && n > c_.max_items(2 * per)) c_.fail(std::string(k.name) + " count " + std::to_string(n) + " is more than the rest of the file can hold");
    for (int64_t i = 0; i < n * per; ++i) c_.next_token();
    if (k.volume) {
      notes_.skipped_elements += n;
      notes_.notes.push_back("skipped " + plural(n, k.name) + " (not tetrahedra), line " + std::to_string(line));
    } else {
      notes_.notes.push_back("Medit keyword " + std::string(k.name) + (k.counted ? " (" + plural(n, "entries") + ")" : "") +
                             " read and ignored");
    }
  }

  // An unknown keyword: its layout is unknown, so skip to the next word starting with a
  // letter (numbers never do; "nan"/"inf" would, and are caught as unknown keywords too).
  void skip_unknown(std::string_view word) {
    if (word.empty() || !std::isalpha(static_cast<unsigned char>(word[0])))
      c_.fail("expected a Medit keyword, found '" + std::string(word.substr(0, 40)) + "'");
    notes_.notes.push_back("unknown Medit keyword '" + std::string(word.substr(0, 40)) + "' at line " +
                           std::to_string(c_.line()) + " skipped");
    while (!c_.at_end()) {
      std::string_view t = c_.peek_token();
      if (std::isalpha(static_cast<unsigned char>(t[0]))) break;
      c_.next_token();
    }
  }

  TextCursor& c_;
  ReadNotes& notes_;
  int64_t nv_ = -1;
  std::vector<Pending> pending_;
};

// Solutions of a .sol file (ASCII), for a mesh of nv vertices and nt tets.
void read_sol_ascii(TextCursor& c, int64_t nv, int64_t nt, Mesh& m, ReadNotes& notes) {
  int field_index = 0;
  while (!c.at_end()) {
    std::string_view word = c.next_token();
    const Keyword* k = find_keyword(word);
    if (!k) c.fail("unknown keyword '" + std::string(word.substr(0, 40)) + "' in a solution file");
    if (k->code == kEnd) break;
    if (k->code == 1) {
      c.next_int();
      continue;
    }
    if (k->code == kDimension) {
      int64_t d = c.next_int();
      if (d != 3) c.fail("Dimension " + std::to_string(d) + ": only 3D solutions are supported");
      continue;
    }
    if (!k->solution) c.fail(std::string("keyword ") + k->name + " in a solution file");
    int64_t n = c.next_count("solution count", c.max_items(2));
    const bool at_vertices = k->code == kSolAtVertices, at_tets = k->code == kSolAtTetrahedra;
    if ((at_vertices && n != nv) || (at_tets && n != nt))
      c.fail(std::string(k->name) + " has " + std::to_string(n) + " entries but the mesh has " +
             (at_vertices ? plural(nv, "vertices") : plural(nt, "tetrahedra")));
    int64_t ntypes = c.next_count("number of solution types", 64);
    std::vector<int> comps;
    for (int64_t t = 0; t < ntypes; ++t) {
      int64_t type = c.next_int();
      int cc = sol_components(type);
      if (cc == 0) c.fail("unknown solution type " + std::to_string(type) + " (known: 1 scalar, 2 vector, 3 symmetric tensor, 4 matrix)");
      comps.push_back(cc);
    }
    int per = 0;
    for (int cc : comps) per += cc;
    if (per > 0 && n > c.max_items(2 * per)) c.fail("solution count " + std::to_string(n) + " is more than the rest of the file can hold");
    if (!at_vertices && !at_tets) {
      for (int64_t i = 0; i < n * per; ++i) c.next_token();
      notes.notes.push_back(std::string("solution keyword ") + k->name + " ignored");
      continue;
    }
    std::vector<Field> fields(comps.size());
    for (size_t f = 0; f < comps.size(); ++f) {
      fields[f].name = "sol" + std::to_string(field_index++);
      fields[f].components = comps[f];
      fields[f].values.resize(static_cast<size_t>(n * comps[f]));
    }
    for (int64_t i = 0; i < n; ++i)
      for (size_t f = 0; f < comps.size(); ++f)
        for (int j = 0; j < comps[f]; ++j)
          fields[f].values[static_cast<size_t>(i * comps[f] + j)] = c.next_finite_double("solution value");
    auto& dst = at_vertices ? m.vertex_fields : m.tet_fields;
    for (auto& f : fields) dst.push_back(std::move(f));
  }
}

// ------------------------------------------------------------------------------ binary

class BinaryReader {
 public:
  BinaryReader(std::string_view data, const std::string& file) : b_(data, file) {
    if (data.size() < 8) b_.fail("too short for a Medit binary file (" + std::to_string(data.size()) + " bytes)");
    int32_t cod = b_.get<int32_t>();
    if (cod == 16777216) b_.set_swap(true);
    else if (cod != 1) b_.fail_at(0, "not a Medit binary file (byte-order code " + std::to_string(cod) + ", expected 1)");
    ver_ = b_.get<int32_t>();
    if (ver_ < 1 || ver_ > 4) b_.fail_at(4, "unsupported Medit binary version " + std::to_string(ver_) + " (1 to 4)");
  }

  // Calls on_keyword(code, count, keyword_offset) for each keyword with the cursor at its
  // data (after the count and, for solutions, left before the types); moves on by the
  // next-keyword position afterwards.
  template <class F>
  void for_each_keyword(F&& on_keyword) {
    for (;;) {
      // libMeshb ends every file with End; a file that stops before it was cut short.
      if (b_.remaining() == 0) b_.fail("unexpected end of file (no End keyword)");
      const size_t at = b_.pos();
      int32_t code = b_.get<int32_t>();
      int64_t next = ver_ >= 3 ? b_.get<int64_t>() : b_.get<int32_t>();
      if (code == kEnd) return;
      if (next != 0 && (next <= static_cast<int64_t>(b_.pos()) || next > static_cast<int64_t>(b_.data().size())))
        b_.fail_at(at, "keyword " + std::to_string(code) + ": next-keyword position " + std::to_string(next) +
                           " is outside the file or not after this keyword");
      const Keyword* k = find_keyword(code);
      int64_t count = 1;
      if (k && k->counted) {
        count = ver_ == 4 ? b_.get<int64_t>() : b_.get<int32_t>();
        if (count < 0) b_.fail_at(at, std::string(k->name) + ": negative count " + std::to_string(count));
      }
      on_keyword(code, k, count, at);
      if (next == 0) return;  // a writer that stopped without End
      b_.set_pos(static_cast<size_t>(next));
    }
  }

  int64_t get_int() { return ver_ == 4 ? b_.get<int64_t>() : b_.get<int32_t>(); }
  double get_real() { return ver_ == 1 ? double(b_.get<float>()) : b_.get<double>(); }
  size_t int_size() const { return ver_ == 4 ? 8 : 4; }
  size_t real_size() const { return ver_ == 1 ? 4 : 8; }
  // Fails unless `n` lines of `bytes` each are left (checked without overflow).
  void need_lines(int64_t n, size_t bytes, const char* what) {
    if (bytes > 0 && static_cast<uint64_t>(n) > b_.remaining() / bytes)
      b_.fail(std::string(what) + " count " + std::to_string(n) + " runs past the end of the file");
  }
  BinaryCursor& cursor() { return b_; }
  int version() const { return ver_; }

 private:
  BinaryCursor b_;
  int ver_ = 0;
};

Mesh read_meshb(std::string_view data, const std::string& file, ReadNotes& notes, io::FileBytes* bytes) {
  BinaryReader r(data, file);
  BinaryCursor& b = r.cursor();
  if (bytes) b.release_through(bytes);
  Mesh m;
  int64_t nv = -1, nonzero_refs = 0;
  std::vector<Pending> pending;
  std::vector<int32_t> tet_refs;

  auto read_elements = [&](const Keyword& k, int64_t n, int per, int keep, std::vector<int32_t>& conn,
                           std::vector<int32_t>& refs) {
    r.need_lines(n, (per + 1) * r.int_size(), k.name);
    const size_t base = conn.size();
    conn.resize(base + static_cast<size_t>(n * keep));
    refs.reserve(refs.size() + static_cast<size_t>(n));
    int64_t max_seen = 0;
    for (int64_t i = 0; i < n; ++i) {
      for (int j = 0; j < per; ++j) {
        const size_t at = b.pos();
        int64_t v = r.get_int();
        const bool keep_bad = io::lenient() && k.code == kTetrahedra;  // the checker reports it
        if (v == 0 && !keep_bad) b.fail_at(at, "index 0 where Medit indices are one-based (" + std::string(k.name) + ")");
        if (v < 0 && !keep_bad) b.fail_at(at, "negative vertex index " + std::to_string(v) + " (" + std::string(k.name) + ")");
        if ((nv >= 0 && v > nv && !keep_bad) || v > std::numeric_limits<int32_t>::max() ||
            v < std::numeric_limits<int32_t>::min() + 1)
          b.fail_at(at, std::string(k.name) + ": " + out_of_range(v, std::max<int64_t>(nv, 0)));
        max_seen = std::max(max_seen, v);
        if (j < keep) conn[base + static_cast<size_t>(i * keep + j)] = static_cast<int32_t>(v - 1);
      }
      const size_t at = b.pos();
      int64_t ref = r.get_int();
      if (ref < std::numeric_limits<int32_t>::min() || ref > std::numeric_limits<int32_t>::max())
        b.fail_at(at, "reference " + std::to_string(ref) + " does not fit in 32 bits");
      refs.push_back(static_cast<int32_t>(ref));
    }
    if (nv < 0 && n > 0 && !(io::lenient() && k.code == kTetrahedra)) pending.push_back({max_seen, 0, k.name});
  };

  r.for_each_keyword([&](int code, const Keyword* k, int64_t n, size_t at) {
    switch (code) {
      case kDimension: {
        int32_t d = b.get<int32_t>();
        if (d != 3) b.fail_at(at, "Dimension " + std::to_string(d) + ": only 3D meshes are supported");
        break;
      }
      case kVertices: {
        if (nv >= 0) b.fail_at(at, "a second Vertices section");
        r.need_lines(n, 3 * r.real_size() + r.int_size(), "vertex");
        if (n > std::numeric_limits<int32_t>::max()) b.fail_at(at, "more vertices than 32-bit indices can address");
        m.points.resize(static_cast<size_t>(3 * n));
        for (int64_t i = 0; i < n; ++i) {
          for (int d = 0; d < 3; ++d) {
            const size_t p = b.pos();
            double x = r.get_real();
            if (!std::isfinite(x) && !io::lenient()) b.fail_at(p, "non-finite vertex coordinate (NaN or infinity)");
            m.points[static_cast<size_t>(3 * i + d)] = x;
          }
          if (r.get_int() != 0) ++nonzero_refs;
        }
        nv = n;
        break;
      }
      case kTetrahedra: read_elements(*k, n, 4, 4, m.tets, tet_refs); break;
      case kTetrahedraP2:
        read_elements(*k, n, 10, 4, m.tets, tet_refs);
        notes.reduced_quadratic_tets += n;
        break;
      case kTriangles: read_elements(*k, n, 3, 3, m.tris, m.tri_tags); break;
      case kEdges: read_elements(*k, n, 2, 2, m.edges, m.edge_tags); break;
      default:
        if (!k) {
          notes.notes.push_back("unknown Medit keyword code " + std::to_string(code) + " at byte " + std::to_string(at) + " skipped");
        } else if (k->volume) {
          notes.skipped_elements += n;
          notes.notes.push_back("skipped " + plural(n, k->name) + " (not tetrahedra)");
        } else if (k->code != 1) {
          notes.notes.push_back("Medit keyword " + std::string(k->name) + (k->counted ? " (" + plural(n, "entries") + ")" : "") +
                                " read and ignored");
        }
        break;
    }
  });
  if (nv < 0) throw InputError(file, "no Vertices section in the file");
  for (const Pending& p : pending)
    if (p.max_index > nv) throw InputError(file, p.keyword + ": " + out_of_range(p.max_index, nv));
  if (!tet_refs.empty() || !m.tets.empty()) m.tet_labels.push_back({"medit:ref", std::move(tet_refs)});
  if (nonzero_refs > 0) notes.notes.push_back(plural(nonzero_refs, "vertices") + " have a non-zero Medit reference (dropped)");
  return m;
}

void read_solb(std::string_view data, const std::string& file, int64_t nv, int64_t nt, Mesh& m, ReadNotes& notes,
               io::FileBytes* bytes) {
  BinaryReader r(data, file);
  BinaryCursor& b = r.cursor();
  if (bytes) b.release_through(bytes);
  int field_index = 0;
  r.for_each_keyword([&](int code, const Keyword* k, int64_t n, size_t at) {
    if (code == kDimension) {
      int32_t d = b.get<int32_t>();
      if (d != 3) b.fail_at(at, "Dimension " + std::to_string(d) + ": only 3D solutions are supported");
      return;
    }
    if (!k || !k->solution) return;
    int32_t ntypes = b.get<int32_t>();
    if (ntypes < 0 || ntypes > 64) b.fail_at(at, "bad number of solution types " + std::to_string(ntypes));
    std::vector<int> comps;
    int per = 0;
    for (int t = 0; t < ntypes; ++t) {
      int32_t type = b.get<int32_t>();
      int cc = sol_components(type);
      if (cc == 0) b.fail_at(at, "unknown solution type " + std::to_string(type));
      comps.push_back(cc);
      per += cc;
    }
    const bool at_vertices = code == kSolAtVertices, at_tets = code == kSolAtTetrahedra;
    if (!at_vertices && !at_tets) {
      notes.notes.push_back(std::string("solution keyword ") + k->name + " ignored");
      return;
    }
    if ((at_vertices && n != nv) || (at_tets && n != nt))
      b.fail_at(at, std::string(k->name) + " has " + std::to_string(n) + " entries but the mesh has " +
                        (at_vertices ? plural(nv, "vertices") : plural(nt, "tetrahedra")));
    r.need_lines(n, static_cast<size_t>(per) * r.real_size(), k->name);
    std::vector<Field> fields(comps.size());
    for (size_t f = 0; f < comps.size(); ++f) {
      fields[f].name = "sol" + std::to_string(field_index++);
      fields[f].components = comps[f];
      fields[f].values.resize(static_cast<size_t>(n * comps[f]));
    }
    for (int64_t i = 0; i < n; ++i)
      for (size_t f = 0; f < comps.size(); ++f)
        for (int j = 0; j < comps[f]; ++j) {
          const size_t p = b.pos();
          double x = r.get_real();
          if (!std::isfinite(x)) b.fail_at(p, "non-finite solution value (NaN or infinity)");
          fields[f].values[static_cast<size_t>(i * comps[f] + j)] = x;
        }
    auto& dst = at_vertices ? m.vertex_fields : m.tet_fields;
    for (auto& f : fields) dst.push_back(std::move(f));
  });
}

bool looks_binary(std::string_view data) {
  if (data.size() < 8) return false;
  int32_t cod;
  std::memcpy(&cod, data.data(), 4);
  return cod == 1 || cod == 16777216;
}

// ------------------------------------------------------------------------------ writing

// How the fields of a mesh become Medit solutions: one solution per field with 1, 3, 6
// or 9 components, else one scalar solution per component.
struct Solution {
  const Field* field;
  int type;        // 1..4
  int component;   // -1: the whole field; else this single component as a scalar
  int size() const { return component >= 0 ? 1 : sol_components(type); }
};

std::vector<Solution> plan_solutions(const std::vector<Field>& fields) {
  std::vector<Solution> out;
  for (const Field& f : fields) {
    switch (f.components) {
      case 1: out.push_back({&f, 1, -1}); break;
      case 3: out.push_back({&f, 2, -1}); break;
      case 6: out.push_back({&f, 3, -1}); break;
      case 9: out.push_back({&f, 4, -1}); break;
      default:
        for (int c = 0; c < f.components; ++c) out.push_back({&f, 1, c});
    }
  }
  return out;
}

const std::vector<int32_t>* tet_refs_of(const Mesh& m) {
  if (const Labels* l = m.find_labels("medit:ref")) return &l->values;
  if (!m.tet_labels.empty()) return &m.tet_labels[0].values;
  return nullptr;
}

int32_t tag_at(const std::vector<int32_t>& tags, int64_t i) {
  return static_cast<size_t>(i) < tags.size() ? tags[static_cast<size_t>(i)] : 0;
}

// Reals in the ASCII files are doubles printed in their shortest round-trip form, so an
// ASCII round trip is exact.
std::string mesh_ascii(const Mesh& m) {
  std::string s;
  s.reserve(static_cast<size_t>(m.points.size() * 22 + m.tets.size() * 9 + m.tris.size() * 9 + 256));
  s += "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n";
  io::append_int(s, m.num_vertices());
  s += '\n';
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    for (int d = 0; d < 3; ++d) {
      io::append_double(s, m.points[static_cast<size_t>(3 * v + d)]);
      s += ' ';
    }
    s += "0\n";
  }
  auto section = [&](const char* name, const std::vector<int32_t>& conn, int per,
                     const std::vector<int32_t>* refs) {
    const int64_t n = static_cast<int64_t>(conn.size()) / per;
    if (n == 0) return;
    s += '\n';
    s += name;
    s += '\n';
    io::append_int(s, n);
    s += '\n';
    for (int64_t i = 0; i < n; ++i) {
      for (int j = 0; j < per; ++j) {
        io::append_int(s, int64_t(conn[static_cast<size_t>(i * per + j)]) + 1);
        s += ' ';
      }
      io::append_int(s, refs ? tag_at(*refs, i) : 0);
      s += '\n';
    }
  };
  section("Tetrahedra", m.tets, 4, tet_refs_of(m));
  section("Triangles", m.tris, 3, &m.tri_tags);
  section("Edges", m.edges, 2, &m.edge_tags);
  s += "\nEnd\n";
  return s;
}

void append_sol_ascii(std::string& s, const char* keyword, int64_t n, const std::vector<Solution>& sols) {
  if (sols.empty()) return;
  s += '\n';
  s += keyword;
  s += '\n';
  io::append_int(s, n);
  s += '\n';
  io::append_int(s, static_cast<int64_t>(sols.size()));
  for (const Solution& x : sols) {
    s += ' ';
    io::append_int(s, x.type);
  }
  s += '\n';
  for (int64_t i = 0; i < n; ++i) {
    for (const Solution& x : sols) {
      const int c = x.field->components;
      if (x.component >= 0) {
        io::append_double(s, x.field->values[static_cast<size_t>(i * c + x.component)]);
        s += ' ';
      } else {
        for (int j = 0; j < c; ++j) {
          io::append_double(s, x.field->values[static_cast<size_t>(i * c + j)]);
          s += ' ';
        }
      }
    }
    s.back() = '\n';
  }
}

// Binary output in the machine's byte order (the byte-order mark tells readers).
class BinaryWriter {
 public:
  explicit BinaryWriter(int version) : ver_(version) {
    put<int32_t>(1);
    put<int32_t>(version);
  }
  template <class T>
  void put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    out_.append(b, sizeof(T));
  }
  // Starts a keyword; its next-keyword position is filled in by the next begin() / end().
  void begin(int code) {
    patch_next();
    put<int32_t>(code);
    next_at_ = out_.size();
    if (ver_ >= 3) put<int64_t>(0);
    else put<int32_t>(0);
  }
  void count(int64_t n) {
    if (ver_ == 4) put<int64_t>(n);
    else put<int32_t>(static_cast<int32_t>(n));
  }
  void integer(int64_t v) {
    if (ver_ == 4) put<int64_t>(v);
    else put<int32_t>(static_cast<int32_t>(v));
  }
  void end() {
    begin(kEnd);
    next_at_ = 0;  // End keeps position 0
  }
  std::string& bytes() { return out_; }

 private:
  void patch_next() {
    if (next_at_ == 0) return;
    const int64_t here = static_cast<int64_t>(out_.size());
    if (ver_ >= 3) std::memcpy(&out_[next_at_], &here, 8);
    else {
      int32_t h = static_cast<int32_t>(here);
      std::memcpy(&out_[next_at_], &h, 4);
    }
  }
  int ver_;
  std::string out_;
  size_t next_at_ = 0;
};

std::string mesh_binary(const Mesh& m, int version) {
  BinaryWriter w(version);
  w.begin(kDimension);
  w.put<int32_t>(3);
  w.begin(kVertices);
  w.count(m.num_vertices());
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    for (int d = 0; d < 3; ++d) w.put<double>(m.points[static_cast<size_t>(3 * v + d)]);
    w.integer(0);
  }
  auto section = [&](int code, const std::vector<int32_t>& conn, int per, const std::vector<int32_t>* refs) {
    const int64_t n = static_cast<int64_t>(conn.size()) / per;
    if (n == 0) return;
    w.begin(code);
    w.count(n);
    for (int64_t i = 0; i < n; ++i) {
      for (int j = 0; j < per; ++j) w.integer(int64_t(conn[static_cast<size_t>(i * per + j)]) + 1);
      w.integer(refs ? tag_at(*refs, i) : 0);
    }
  };
  section(kTetrahedra, m.tets, 4, tet_refs_of(m));
  section(kTriangles, m.tris, 3, &m.tri_tags);
  section(kEdges, m.edges, 2, &m.edge_tags);
  w.end();
  return std::move(w.bytes());
}

void append_sol_binary(BinaryWriter& w, int code, int64_t n, const std::vector<Solution>& sols) {
  if (sols.empty()) return;
  w.begin(code);
  w.count(n);
  w.put<int32_t>(static_cast<int32_t>(sols.size()));
  for (const Solution& x : sols) w.put<int32_t>(x.type);
  for (int64_t i = 0; i < n; ++i)
    for (const Solution& x : sols) {
      const int c = x.field->components;
      if (x.component >= 0) w.put<double>(x.field->values[static_cast<size_t>(i * c + x.component)]);
      else
        for (int j = 0; j < c; ++j) w.put<double>(x.field->values[static_cast<size_t>(i * c + j)]);
    }
}

// Bytes of the binary mesh, to choose between version 2 (32-bit positions) and 3.
uint64_t binary_size_estimate(const Mesh& m) {
  return 64 + m.points.size() / 3 * 28 + m.tets.size() / 4 * 20 + m.tris.size() / 3 * 16 + m.edges.size() / 2 * 12;
}

}  // namespace

// ------------------------------------------------------------------------------ entry points

// The text of `file` without its comments, and a cursor over it that gives the file's pages back
// behind itself (blank_comments' copy, when it makes one, has taken them all).
TextCursor text_cursor(io::FileBytes& file, const std::string& path, std::string& storage) {
  TextCursor c(io::blank_comments(file.view(), storage, &file), path);
  if (storage.empty()) c.release_through(&file);
  else file.done();
  return c;
}

Mesh read_medit(const std::string& path, ReadNotes& notes, bool read_sol) {
  io::FileBytes file(path);
  const std::string_view data = file.view();
  if (data.empty()) throw InputError(path, "empty file");
  const bool binary = looks_binary(data);
  Mesh m;
  if (binary) {
    m = read_meshb(data, path, notes, &file);
  } else {
    std::string storage;
    TextCursor c = text_cursor(file, path, storage);
    AsciiReader r(c, notes);
    m = r.read();
  }
  if (!read_sol) return m;
  // The solution file beside the mesh: FILE.solb next to a .meshb (falling back to
  // FILE.sol), FILE.sol next to a .mesh (falling back to FILE.solb).
  std::error_code ec;
  std::string sol;
  const char* order[2] = {binary ? ".solb" : ".sol", binary ? ".sol" : ".solb"};
  for (const char* ext : order) {
    std::string p = io::replace_extension(path, ext);
    if (std::filesystem::is_regular_file(p, ec)) {
      sol = p;
      break;
    }
  }
  if (sol.empty()) return m;
  io::FileBytes sfile(sol);
  const std::string_view sdata = sfile.view();
  if (sdata.empty()) throw InputError(sol, "empty solution file");
  if (looks_binary(sdata)) {
    read_solb(sdata, sol, m.num_vertices(), m.num_tets(), m, notes, &sfile);
  } else {
    std::string storage;
    TextCursor c = text_cursor(sfile, sol, storage);
    read_sol_ascii(c, m.num_vertices(), m.num_tets(), m, notes);
  }
  notes.notes.push_back("read " + plural(static_cast<int64_t>(m.vertex_fields.size()), "vertex fields") + " and " +
                        plural(static_cast<int64_t>(m.tet_fields.size()), "tet fields") + " from " + sol);
  return m;
}

void write_medit(const std::string& path, const Mesh& m, const WriteOptions& options) {
  const std::string ext = io::extension_of(path);
  const bool binary = ext == ".meshb" || (ext != ".mesh" && options.binary);
  const std::vector<Solution> vsols = plan_solutions(m.vertex_fields);
  const std::vector<Solution> tsols = plan_solutions(m.tet_fields);
  const bool with_sol = !vsols.empty() || !tsols.empty();
  const std::string sol_path = io::replace_extension(path, binary ? ".solb" : ".sol");
  for (const Field& f : m.vertex_fields)
    if (f.components < 1 || f.values.size() != static_cast<size_t>(m.num_vertices() * f.components))
      throw OutputError(path + ": vertex field '" + f.name + "' does not have one value per vertex and component");
  for (const Field& f : m.tet_fields)
    if (f.components < 1 || f.values.size() != static_cast<size_t>(m.num_tets() * f.components))
      throw OutputError(path + ": tet field '" + f.name + "' does not have one value per tet and component");

  std::string mesh_bytes, sol_bytes;
  if (binary) {
    const int version = binary_size_estimate(m) < (uint64_t(1) << 31) ? 2 : 3;
    mesh_bytes = mesh_binary(m, version);
    if (with_sol) {
      uint64_t sol_size = 64;
      for (const Solution& x : vsols) sol_size += uint64_t(m.num_vertices()) * uint64_t(x.size()) * 8;
      for (const Solution& x : tsols) sol_size += uint64_t(m.num_tets()) * uint64_t(x.size()) * 8;
      BinaryWriter w(sol_size < (uint64_t(1) << 31) ? 2 : 3);
      w.begin(kDimension);
      w.put<int32_t>(3);
      append_sol_binary(w, kSolAtVertices, m.num_vertices(), vsols);
      append_sol_binary(w, kSolAtTetrahedra, m.num_tets(), tsols);
      w.end();
      sol_bytes = std::move(w.bytes());
    }
  } else {
    mesh_bytes = mesh_ascii(m);
    if (with_sol) {
      sol_bytes = "MeshVersionFormatted 2\n\nDimension 3\n";
      append_sol_ascii(sol_bytes, "SolAtVertices", m.num_vertices(), vsols);
      append_sol_ascii(sol_bytes, "SolAtTetrahedra", m.num_tets(), tsols);
      sol_bytes += "\nEnd\n";
    }
  }

  io::AtomicFile mesh_file(path, true);
  mesh_file.write(mesh_bytes.data(), mesh_bytes.size());
  if (with_sol) {
    io::AtomicFile sol_file(sol_path, true);
    sol_file.write(sol_bytes.data(), sol_bytes.size());
    io::commit_all({&mesh_file, &sol_file});
  } else {
    mesh_file.commit();
    // A solution file left beside the target from an earlier mesh would no longer match.
    std::error_code ec;
    std::filesystem::remove(io::replace_extension(path, ".sol"), ec);
    std::filesystem::remove(io::replace_extension(path, ".solb"), ec);
  }
}

}  // namespace tc
