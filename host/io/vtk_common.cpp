#include "io/vtk_common.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "io/io_util.hpp"

namespace tc::io::vtk {

size_t type_size(NumType t) {
  switch (t) {
    case NumType::Int8: case NumType::UInt8: return 1;
    case NumType::Int16: case NumType::UInt16: return 2;
    case NumType::Int32: case NumType::UInt32: case NumType::Float32: return 4;
    case NumType::Int64: case NumType::UInt64: case NumType::Float64: return 8;
  }
  return 1;
}

bool type_is_integer(NumType t) { return t != NumType::Float32 && t != NumType::Float64; }

static std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = char(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

bool parse_legacy_type(std::string_view name, NumType& out) {
  static const struct { const char* name; NumType type; } kTypes[] = {
      {"char", NumType::Int8},           {"signed_char", NumType::Int8},
      {"unsigned_char", NumType::UInt8}, {"short", NumType::Int16},
      {"unsigned_short", NumType::UInt16}, {"int", NumType::Int32},
      {"unsigned_int", NumType::UInt32}, {"long", NumType::Int64},
      {"unsigned_long", NumType::UInt64}, {"vtktypeint64", NumType::Int64},
      {"vtktypeuint64", NumType::UInt64}, {"vtkidtype", NumType::Int64},
      {"vtktypeint32", NumType::Int32},  {"vtktypeuint32", NumType::UInt32},
      {"float", NumType::Float32},       {"double", NumType::Float64},
  };
  std::string l = lower(name);
  for (const auto& t : kTypes)
    if (l == t.name) {
      out = t.type;
      return true;
    }
  return false;
}

bool parse_xml_type(std::string_view name, NumType& out) {
  static const struct { const char* name; NumType type; } kTypes[] = {
      {"Int8", NumType::Int8},     {"UInt8", NumType::UInt8},     {"Int16", NumType::Int16},
      {"UInt16", NumType::UInt16}, {"Int32", NumType::Int32},     {"UInt32", NumType::UInt32},
      {"Int64", NumType::Int64},   {"UInt64", NumType::UInt64},   {"Float32", NumType::Float32},
      {"Float64", NumType::Float64}, {"Char", NumType::Int8},     {"vtkIdType", NumType::Int64},
  };
  for (const auto& t : kTypes)
    if (name == t.name) {
      out = t.type;
      return true;
    }
  return false;
}

template <class S, class T>
static int64_t convert_as(const char* bytes, size_t n, bool swap, T* out) {
  for (size_t i = 0; i < n; ++i) {
    S v;
    std::memcpy(&v, bytes + i * sizeof(S), sizeof(S));
    if (swap) v = BinaryCursor::byteswap_value(v);
    if constexpr (std::is_floating_point_v<S> && std::is_integral_v<T>) {
      // Integer data (cells, offsets, labels) stored as floats: a value with a fraction,
      // NaN, or outside T has no integer value (converting it would be undefined).
      const double d = static_cast<double>(v);
      if (!(d == std::floor(d) && d >= -0x1p63 && d < 0x1p63)) return static_cast<int64_t>(i);
    }
    out[i] = static_cast<T>(v);
  }
  return -1;
}

template <class T>
int64_t convert_raw(const char* bytes, NumType t, size_t n, bool swap, T* out) {
  switch (t) {
    case NumType::Int8: return convert_as<int8_t>(bytes, n, swap, out);
    case NumType::UInt8: return convert_as<uint8_t>(bytes, n, swap, out);
    case NumType::Int16: return convert_as<int16_t>(bytes, n, swap, out);
    case NumType::UInt16: return convert_as<uint16_t>(bytes, n, swap, out);
    case NumType::Int32: return convert_as<int32_t>(bytes, n, swap, out);
    case NumType::UInt32: return convert_as<uint32_t>(bytes, n, swap, out);
    case NumType::Int64: return convert_as<int64_t>(bytes, n, swap, out);
    case NumType::UInt64: return convert_as<uint64_t>(bytes, n, swap, out);
    case NumType::Float32: return convert_as<float>(bytes, n, swap, out);
    case NumType::Float64: return convert_as<double>(bytes, n, swap, out);
  }
  return -1;
}
template int64_t convert_raw<double>(const char*, NumType, size_t, bool, double*);
template int64_t convert_raw<int64_t>(const char*, NumType, size_t, bool, int64_t*);

int64_t first_non_finite(const std::vector<double>& v) {
  for (size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) return static_cast<int64_t>(i);
  return -1;
}

void assemble(Mesh& mesh, ReadNotes& notes, const Cells& cells, std::vector<RawArray>& point_arrays,
              std::vector<RawArray>& cell_arrays, const std::function<void(const std::string&)>& fail_cells) {
  const int64_t nv = mesh.num_vertices();
  const int64_t nc = cells.num_cells();
  std::vector<int64_t> tet_cells;  // cell index of each tet, for the cell data
  int64_t skipped = 0, quadratic = 0;
  auto node_count_ok = [&](int64_t c, int64_t have, int64_t need, const char* what) {
    if (have != need)
      fail_cells("cell " + std::to_string(c) + " (" + what + ") has " + std::to_string(have) + " points, expected " +
                 std::to_string(need));
  };
  auto check_index = [&](int64_t c, int64_t v) {
    if (v < 0 || v >= nv)
      fail_cells("cell " + std::to_string(c) + " refers to point " + std::to_string(v) + ", but there are " +
                 std::to_string(nv) + " points");
    return static_cast<int32_t>(v);
  };
  for (int64_t c = 0; c < nc; ++c) {
    const int64_t b = cells.offsets[c], n = cells.offsets[c + 1] - b;
    const int64_t* p = cells.conn.data() + b;
    switch (cells.types[c]) {
      case kTet:
      case kQuadTet:
        if (cells.types[c] == kTet) {
          node_count_ok(c, n, 4, "tetrahedron");
        } else {
          node_count_ok(c, n, 10, "quadratic tetrahedron");
          ++quadratic;
        }
        for (int k = 0; k < 4; ++k) mesh.tets.push_back(check_index(c, p[k]));
        tet_cells.push_back(c);
        break;
      case kTriangle:
        node_count_ok(c, n, 3, "triangle");
        for (int k = 0; k < 3; ++k) mesh.tris.push_back(check_index(c, p[k]));
        mesh.tri_tags.push_back(0);
        break;
      case kLine:
        node_count_ok(c, n, 2, "line");
        for (int k = 0; k < 2; ++k) mesh.edges.push_back(check_index(c, p[k]));
        mesh.edge_tags.push_back(0);
        break;
      default:
        ++skipped;
        // Indices of skipped cells are still checked: a bad index means a bad file.
        for (int64_t k = 0; k < n; ++k) check_index(c, p[k]);
        break;
    }
  }
  if (skipped > 0) {
    notes.skipped_elements += skipped;
    notes.notes.push_back("skipped " + std::to_string(skipped) + " cells that are not tetrahedra, triangles or lines");
  }
  if (quadratic > 0) {
    notes.reduced_quadratic_tets += quadratic;
    notes.notes.push_back("kept the 4 corner points of " + std::to_string(quadratic) + " quadratic tetrahedra");
  }

  for (RawArray& a : point_arrays) {
    Field f;
    f.name = a.name;
    f.components = a.components;
    f.values = std::move(a.values);
    mesh.vertex_fields.push_back(std::move(f));
  }

  const bool all_tets = static_cast<int64_t>(tet_cells.size()) == nc;
  for (RawArray& a : cell_arrays) {
    const size_t comps = static_cast<size_t>(a.components);
    std::vector<double> vals;
    if (all_tets) {
      vals = std::move(a.values);
    } else {
      vals.reserve(tet_cells.size() * comps);
      for (int64_t c : tet_cells)
        vals.insert(vals.end(), a.values.begin() + c * comps, a.values.begin() + (c + 1) * comps);
    }
    bool as_labels = a.integer && a.components == 1;
    if (as_labels)
      for (double v : vals)
        if (!(v >= std::numeric_limits<int32_t>::min() && v <= std::numeric_limits<int32_t>::max())) {
          as_labels = false;
          notes.notes.push_back("cell array '" + a.name + "' has values outside the int32 range; kept as a field");
          break;
        }
    if (as_labels) {
      Labels l;
      l.name = a.name;
      l.values.resize(vals.size());
      for (size_t i = 0; i < vals.size(); ++i) l.values[i] = static_cast<int32_t>(vals[i]);
      mesh.tet_labels.push_back(std::move(l));
    } else {
      Field f;
      f.name = a.name;
      f.components = a.components;
      f.values = std::move(vals);
      mesh.tet_fields.push_back(std::move(f));
    }
  }
}

}  // namespace tc::io::vtk
