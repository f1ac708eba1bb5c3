// Pieces shared by the VTK legacy (.vtk) and VTK XML (.vtu) readers and writers: numeric
// type names, conversion of raw arrays, and the mapping from VTK cells and cell/point data
// to tc::Mesh (which keeps tets only, plus triangles and lines as tagged features).
#pragma once

#include <bit>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::io::vtk {

enum class NumType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

size_t type_size(NumType t);
bool type_is_integer(NumType t);
// Legacy names (case-insensitive): char, unsigned_char, short, ..., long (8 bytes, as
// vtkDataWriter writes it on 64-bit systems), vtktypeint64, vtkIdType, float, double.
bool parse_legacy_type(std::string_view name, NumType& out);
// XML names: Int8 ... UInt64, Float32, Float64 (also the old "Int", "Float" spellings are not VTK's).
bool parse_xml_type(std::string_view name, NumType& out);

// Converts n values of type t stored at `bytes` (native order unless swap) to T. Returns
// the index of the first value T cannot hold (when T is an integer type: a floating-point
// value with a fraction, NaN, or out of range), after which `out` is incomplete; else -1.
template <class T>
int64_t convert_raw(const char* bytes, NumType t, size_t n, bool swap, T* out);

inline constexpr bool kHostLittle = std::endian::native == std::endian::little;

// A data array as read from the file, before it is assigned to vertices or tets.
struct RawArray {
  std::string name;
  int components = 1;
  bool integer = false;         // stored with an integer type in the file
  std::vector<double> values;   // tuples * components
};

// VTK cells in the offsets/connectivity form (legacy 4.x lists are converted to it).
struct Cells {
  std::vector<int64_t> offsets;  // num_cells + 1, offsets[0] = 0, non-decreasing
  std::vector<int64_t> conn;
  std::vector<int64_t> types;    // num_cells
  int64_t num_cells() const { return static_cast<int64_t>(types.size()); }
};

// Cell types we keep.
inline constexpr int kLine = 3, kTriangle = 5, kTet = 10, kQuadTet = 24;

// Fills mesh.tets / tris / edges from `cells` and assigns point and cell arrays:
// point arrays -> vertex_fields; cell arrays of an integer type with one component whose
// tet values fit in int32 -> tet_labels, others -> tet_fields (tet values only, tet order).
// Other cell types are skipped and counted. `fail_cells` throws (with the file position of
// the cell block) on a bad cell: wrong node count or a point index out of range.
void assemble(Mesh& mesh, ReadNotes& notes, const Cells& cells, std::vector<RawArray>& point_arrays,
              std::vector<RawArray>& cell_arrays, const std::function<void(const std::string&)>& fail_cells);

// Index of the first non-finite coordinate value, or -1.
int64_t first_non_finite(const std::vector<double>& v);

}  // namespace tc::io::vtk
