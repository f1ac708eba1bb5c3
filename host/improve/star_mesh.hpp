// The improvement's collapse step on part of a mesh: the stars of the vertices it may collapse,
// cut out, coarsened by the sequential method, and spliced back.
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/sequential_run.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::improve_detail {

// The tets with a vertex in `mask` (the stars of the vertices whose edges the step may
// collapse: all that a collapse between two of them reads or changes, the surface guard's S
// faces near them included) with their vertices, both in the whole mesh's order, so that the
// sequential method's queue breaks ties as on the whole mesh; the labels, fields, and a last tet
// field with each tet's index in the whole mesh. Why not the whole mesh: the sequential
// method's set-up (faces, classes, guard grid, compaction) is proportional to the mesh, and the
// step has a few hundred edges in a mesh of a hundred thousand tets or more.
// verts: star vertex -> whole vertex; tets: star tet -> whole tet.
struct StarMesh {
  Mesh mesh;
  std::vector<int32_t> verts, tets;
};
StarMesh star_mesh(const Mesh& whole, const std::vector<uint8_t>& mask);

// The whole mesh after `run` (SequentialRun::keep_origin called before its first step) coarsened
// the star mesh `s` in place: what the same run would have left of the whole mesh, vertices and
// tets in its order as its compaction keeps them, triangles and edges remapped as
// SequentialRun::finish remaps them.
void splice(Mesh& whole, const StarMesh& s, const sequential_detail::SequentialRun& run);

}  // namespace tc::improve_detail
