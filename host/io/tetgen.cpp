// TetGen meshes: FILE.node + FILE.ele (+ FILE.face when present).
//
//   .node  header "n 3 nattr nbmarker"; lines "index x y z [attr...] [marker]"
//   .ele   header "n 4|10 nattr";        lines "index v0 v1 v2 v3 [6 more for tet10] [attr...]"
//   .face  header "n nbmarker";          lines "index v0 v1 v2 [marker]"
// '#' starts a comment. The first node index (0 or 1) decides the numbering of the whole
// mesh, as in TetGen; node indices must then run consecutively (TetGen itself writes them
// so, and a gap would silently shift every reference). Each record sits on one line;
// values beyond those the header announces are ignored, as TetGen does (e.g. the
// neighbour columns of .face files written with -nn). Optional header fields default to 0.
//
// What we keep: node attributes -> vertex fields "tetgen:attr0", "tetgen:attr1", ...
// (node boundary markers are dropped, noted when non-zero); element attribute 0 (the
// region attribute of -A) -> label "tetgen:region", further ones -> "tetgen:attr1", ...;
// an element attribute with a non-integer value stays a tet field of the same name.
// tet10 elements are kept as their 4 corners. .face markers -> tri_tags.
//
// Orientation: TetGen 1.5 (Debian 1.5.0, `tetgen -p cube.off`) writes every tet with
// orient3d(v0,v1,v2,v3) = dot(cross(v1-v0, v2-v0), v3-v0) > 0, i.e. positively in our
// convention (TetGen's own Shewchuk orient3d, which has the opposite sign, is negative for
// them); reading such a file back with `tetgen -r` keeps the vertex order, while it
// reorders a negatively oriented input tet. So the writer writes the tets as they are.
//
// Writer: one-based .node (vertex fields flattened to attributes, in order), .ele (every
// label array, then every tet field component, as attributes; the first attribute is what
// TetGen treats as the region), .face when the mesh has triangles (tags as markers). All
// files are committed together; a stale .face beside the target is removed when the mesh
// has no triangles.
#include <cmath>
#include <filesystem>
#include <limits>
#include <string_view>
#include <string>
#include <vector>

#include "io/comments.hpp"
#include "io/io_util.hpp"
#include "tetcollapse/io.hpp"

namespace tc {
namespace {

using io::TextCursor;

// Reads the records of a TetGen file: one record per line, checked to stay on its line
// so that a short line is reported where it is rather than as garbage further on.
class Records {
 public:
  // Over `file`'s bytes, given back behind the cursor (or at once, when blank_comments copied them).
  Records(io::FileBytes& file, const std::string& path) : c_(io::blank_comments(file.view(), storage_, &file), path) {
    if (storage_.empty()) c_.release_through(&file);
    else file.done();
  }

  // Starts a record; `what` (and, for data records, "i of n") names it for "unexpected
  // end of file" messages. The message is built only on failure: this runs per line.
  void begin(const char* what, int64_t i = -1, int64_t n = 0) {
    if (c_.at_end()) {
      std::string msg = "unexpected end of file (expected ";
      msg += what;
      if (i >= 0) msg.append(" ").append(std::to_string(i + 1)).append(" of ").append(std::to_string(n));
      c_.fail(msg + ")");
    }
    line_ = c_.line();
  }
  // True when the current record has another value on its line.
  bool more() { return !c_.at_end() && c_.line() == line_; }
  void need(const char* what) {
    if (!more()) throw InputError(c_.file(), line_, std::string("line ends early: expected ") + what);
  }
  int64_t integer(const char* what) {
    need(what);
    return c_.next_int();
  }
  int64_t count(const char* what, int64_t max) {
    need(what);
    return c_.next_count(what, max);
  }
  double real(const char* what) {
    need(what);
    return c_.next_finite_double(what);
  }
  // Ends the record: the rest of its line is ignored.
  void end() {
    if (!c_.at_end() && c_.line() == line_) c_.skip_line();
  }
  // After the last record: anything left means the header's count was wrong.
  void expect_end(int64_t n, const char* what) {
    if (!c_.at_end())
      c_.fail("more data after the last " + std::string(what) + " (the header says " + std::to_string(n) + ")");
  }
  [[noreturn]] void fail(const std::string& reason) const { throw InputError(c_.file(), line_, reason); }
  int64_t max_items(int64_t min_chars) const { return c_.max_items(min_chars); }
  int64_t line() const { return line_; }

 private:
  std::string storage_;
  TextCursor c_;
  int64_t line_ = 0;
};

struct NodeFile {
  int64_t base = 0;  // 0 or 1
  int64_t n = 0;
};

NodeFile read_node(const std::string& path, Mesh& m, ReadNotes& notes) {
  io::FileBytes file(path);
  Records r(file, path);
  r.begin("the .node header");
  // Shortest node line: "0 0 0 0\n".
  const int64_t n = r.count("node count", r.max_items(8));
  if (n > std::numeric_limits<int32_t>::max()) r.fail("more nodes than 32-bit indices can address");
  const int64_t dim = r.more() ? r.integer("dimension") : 3;
  if (dim != 3) r.fail("dimension " + std::to_string(dim) + ": only 3D meshes are supported");
  const int64_t nattr = r.more() ? r.count("attribute count", 1000) : 0;
  const int64_t nbmarker = r.more() ? r.integer("boundary marker flag") : 0;
  if (nbmarker != 0 && nbmarker != 1) r.fail("boundary marker flag " + std::to_string(nbmarker) + " is not 0 or 1");
  r.end();
  if (n > r.max_items(2 * (4 + nattr + nbmarker)))
    r.fail("node count " + std::to_string(n) + " is more than the rest of the file can hold");

  NodeFile nf;
  nf.n = n;
  m.points.resize(static_cast<size_t>(3 * n));
  std::vector<Field> attrs(static_cast<size_t>(nattr));
  for (int64_t a = 0; a < nattr; ++a) {
    attrs[a].name = "tetgen:attr" + std::to_string(a);
    attrs[a].values.resize(static_cast<size_t>(n));
  }
  int64_t nonzero_markers = 0;
  for (int64_t i = 0; i < n; ++i) {
    r.begin("node", i, n);
    const int64_t index = r.integer("node index");
    if (i == 0) {
      if (index != 0 && index != 1) r.fail("first node index " + std::to_string(index) + " is not 0 or 1");
      nf.base = index;
    } else if (index != nf.base + i) {
      r.fail("node index " + std::to_string(index) + " out of sequence (expected " + std::to_string(nf.base + i) + ")");
    }
    for (int d = 0; d < 3; ++d) m.points[static_cast<size_t>(3 * i + d)] = r.real("node coordinate");
    for (int64_t a = 0; a < nattr; ++a) attrs[a].values[static_cast<size_t>(i)] = r.real("node attribute");
    if (nbmarker && r.integer("boundary marker") != 0) ++nonzero_markers;
    r.end();
  }
  r.expect_end(n, "node");
  for (auto& f : attrs) m.vertex_fields.push_back(std::move(f));
  if (nonzero_markers > 0)
    notes.notes.push_back(std::to_string(nonzero_markers) + " nodes have a non-zero TetGen boundary marker (dropped)");
  return nf;
}

// A vertex reference of an element line, converted to zero-based.
int32_t vertex_ref(Records& r, const NodeFile& nf, const char* what) {
  const int64_t v = r.integer(what);
  // (the checker's reading keeps an element's bad index for tc::check_mesh to report)
  if (io::lenient() && std::string_view(what).find("tet") != std::string_view::npos &&
      v - nf.base >= std::numeric_limits<int32_t>::min() + 1 && v - nf.base <= std::numeric_limits<int32_t>::max())
    return static_cast<int32_t>(v - nf.base);
  if (v < nf.base || v >= nf.base + nf.n) {
    if (v == 0 && nf.base == 1) r.fail("index 0 where the .node file numbers its nodes from 1");
    r.fail("node index " + std::to_string(v) + " is out of range (the .node file has nodes " + std::to_string(nf.base) +
           " to " + std::to_string(nf.base + nf.n - 1) + ")");
  }
  return static_cast<int32_t>(v - nf.base);
}

void read_ele(const std::string& path, const NodeFile& nf, Mesh& m, ReadNotes& notes) {
  io::FileBytes file(path);
  Records r(file, path);
  r.begin("the .ele header");
  const int64_t n = r.count("element count", r.max_items(10));
  const int64_t per = r.more() ? r.integer("nodes per tetrahedron") : 4;
  if (per != 4 && per != 10) r.fail("nodes per tetrahedron " + std::to_string(per) + " is not 4 or 10");
  const int64_t nattr = r.more() ? r.count("attribute count", 1000) : 0;
  r.end();
  if (n > r.max_items(2 * (1 + per + nattr)))
    r.fail("element count " + std::to_string(n) + " is more than the rest of the file can hold");
  if (n > std::numeric_limits<int32_t>::max()) r.fail("more elements than 32-bit indices can address");

  m.tets.resize(static_cast<size_t>(4 * n));
  std::vector<std::vector<double>> attrs(static_cast<size_t>(nattr), std::vector<double>(static_cast<size_t>(n)));
  for (int64_t i = 0; i < n; ++i) {
    r.begin("element", i, n);
    r.integer("element index");
    for (int j = 0; j < per; ++j) {
      int32_t v = vertex_ref(r, nf, "tet node index");
      if (j < 4) m.tets[static_cast<size_t>(4 * i + j)] = v;
    }
    for (int64_t a = 0; a < nattr; ++a) attrs[a][static_cast<size_t>(i)] = r.real("element attribute");
    r.end();
  }
  r.expect_end(n, "element");
  if (per == 10) notes.reduced_quadratic_tets += n;
  for (int64_t a = 0; a < nattr; ++a) {
    const std::string name = a == 0 ? "tetgen:region" : "tetgen:attr" + std::to_string(a);
    bool integral = true;
    for (double x : attrs[a])
      integral = integral && x == std::floor(x) && x >= std::numeric_limits<int32_t>::min() &&
                 x <= std::numeric_limits<int32_t>::max();
    if (integral) {
      Labels l{name, std::vector<int32_t>(static_cast<size_t>(n))};
      for (int64_t i = 0; i < n; ++i) l.values[static_cast<size_t>(i)] = static_cast<int32_t>(attrs[a][static_cast<size_t>(i)]);
      m.tet_labels.push_back(std::move(l));
    } else {
      m.tet_fields.push_back({name, 1, std::move(attrs[a])});
      notes.notes.push_back("element attribute " + std::to_string(a) + " has non-integer values; kept as tet field '" + name + "'");
    }
  }
}

void read_face(const std::string& path, const NodeFile& nf, Mesh& m) {
  io::FileBytes file(path);
  Records r(file, path);
  r.begin("the .face header");
  const int64_t n = r.count("face count", r.max_items(8));
  const int64_t nbmarker = r.more() ? r.integer("boundary marker flag") : 0;
  if (nbmarker != 0 && nbmarker != 1) r.fail("boundary marker flag " + std::to_string(nbmarker) + " is not 0 or 1");
  r.end();
  if (n > r.max_items(2 * (4 + nbmarker)))
    r.fail("face count " + std::to_string(n) + " is more than the rest of the file can hold");
  m.tris.resize(static_cast<size_t>(3 * n));
  m.tri_tags.assign(static_cast<size_t>(n), 0);
  for (int64_t i = 0; i < n; ++i) {
    r.begin("face", i, n);
    r.integer("face index");
    for (int j = 0; j < 3; ++j) m.tris[static_cast<size_t>(3 * i + j)] = vertex_ref(r, nf, "node index");
    if (nbmarker) {
      const int64_t t = r.integer("boundary marker");
      if (t < std::numeric_limits<int32_t>::min() || t > std::numeric_limits<int32_t>::max())
        r.fail("boundary marker " + std::to_string(t) + " does not fit in 32 bits");
      m.tri_tags[static_cast<size_t>(i)] = static_cast<int32_t>(t);
    }
    r.end();
  }
  r.expect_end(n, "face");
}

// FILE from FILE.node / FILE.ele / FILE.face; anything else (e.g. "cube.1") is FILE itself.
std::string base_of(const std::string& path) {
  const std::string ext = io::extension_of(path);
  if (ext == ".node" || ext == ".ele" || ext == ".face") return path.substr(0, path.size() - ext.size());
  return path;
}

}  // namespace

Mesh read_tetgen(const std::string& path, ReadNotes& notes) {
  const std::string base = base_of(path);
  Mesh m;
  const NodeFile nf = read_node(base + ".node", m, notes);
  read_ele(base + ".ele", nf, m, notes);
  std::error_code ec;
  if (std::filesystem::is_regular_file(base + ".face", ec)) read_face(base + ".face", nf, m);
  return m;
}

void write_tetgen(const std::string& path, const Mesh& m, const WriteOptions&) {
  const std::string base = base_of(path);
  const int64_t nv = m.num_vertices(), nt = m.num_tets(), nf = m.num_tris();
  int64_t nvattr = 0, ntattr = static_cast<int64_t>(m.tet_labels.size());
  for (const Field& f : m.vertex_fields) {
    if (f.components < 1 || f.values.size() != static_cast<size_t>(nv * f.components))
      throw OutputError(path + ": vertex field '" + f.name + "' does not have one value per vertex and component");
    nvattr += f.components;
  }
  for (const Field& f : m.tet_fields) {
    if (f.components < 1 || f.values.size() != static_cast<size_t>(nt * f.components))
      throw OutputError(path + ": tet field '" + f.name + "' does not have one value per tet and component");
    ntattr += f.components;
  }
  for (const Labels& l : m.tet_labels)
    if (l.values.size() != static_cast<size_t>(nt))
      throw OutputError(path + ": label array '" + l.name + "' does not have one value per tet");

  std::string node;
  node.reserve(static_cast<size_t>(nv * (70 + 22 * nvattr)));
  node += "# written by tetcollapse\n";
  io::append_int(node, nv);
  node += " 3 ";
  io::append_int(node, nvattr);
  node += " 0\n";
  for (int64_t v = 0; v < nv; ++v) {
    io::append_int(node, v + 1);
    for (int d = 0; d < 3; ++d) {
      node += ' ';
      io::append_double(node, m.points[static_cast<size_t>(3 * v + d)]);
    }
    for (const Field& f : m.vertex_fields)
      for (int c = 0; c < f.components; ++c) {
        node += ' ';
        io::append_double(node, f.values[static_cast<size_t>(v * f.components + c)]);
      }
    node += '\n';
  }

  std::string ele;
  ele.reserve(static_cast<size_t>(nt * (40 + 12 * ntattr)));
  ele += "# written by tetcollapse\n";
  io::append_int(ele, nt);
  ele += " 4 ";
  io::append_int(ele, ntattr);
  ele += '\n';
  for (int64_t t = 0; t < nt; ++t) {
    io::append_int(ele, t + 1);
    for (int j = 0; j < 4; ++j) {
      ele += ' ';
      io::append_int(ele, int64_t(m.tets[static_cast<size_t>(4 * t + j)]) + 1);
    }
    for (const Labels& l : m.tet_labels) {
      ele += ' ';
      io::append_int(ele, l.values[static_cast<size_t>(t)]);
    }
    for (const Field& f : m.tet_fields)
      for (int c = 0; c < f.components; ++c) {
        ele += ' ';
        io::append_double(ele, f.values[static_cast<size_t>(t * f.components + c)]);
      }
    ele += '\n';
  }

  io::AtomicFile node_file(base + ".node", true), ele_file(base + ".ele", true);
  node_file.write(node.data(), node.size());
  ele_file.write(ele.data(), ele.size());
  if (nf == 0) {
    io::commit_all({&node_file, &ele_file});
    // A .face left beside the target from an earlier mesh would be read with this one.
    std::error_code ec;
    std::filesystem::remove(base + ".face", ec);
    return;
  }
  std::string face;
  face.reserve(static_cast<size_t>(nf * 40));
  face += "# written by tetcollapse\n";
  io::append_int(face, nf);
  face += " 1\n";
  for (int64_t i = 0; i < nf; ++i) {
    io::append_int(face, i + 1);
    for (int j = 0; j < 3; ++j) {
      face += ' ';
      io::append_int(face, int64_t(m.tris[static_cast<size_t>(3 * i + j)]) + 1);
    }
    face += ' ';
    io::append_int(face, static_cast<size_t>(i) < m.tri_tags.size() ? m.tri_tags[static_cast<size_t>(i)] : 0);
    face += '\n';
  }
  io::AtomicFile face_file(base + ".face", true);
  face_file.write(face.data(), face.size());
  io::commit_all({&node_file, &ele_file, &face_file});
}

}  // namespace tc
