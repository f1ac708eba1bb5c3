// The selection's result (selection.hpp), which the surface guard and the compaction read.
#pragma once

#include <cstdint>

#include "collapse/launch.hpp"

namespace tc::collapse_detail {

// Written by the selection that runs (admissible() included); read by the surface guard, the
// compaction, remember_for_carry and the carried build_connectivity.
struct SelectionResult {
  // The edges to collapse, the direction of each (which end point survives, where it goes), per
  // vertex the collapse that moves or removes it (-1: none), and why a tested edge was refused
  // (Reason).
  DeviceBuffer<uint32_t> edges_are_final;
  DeviceBuffer<uint8_t> edges2dir, edges2reason;
  DeviceBuffer<int32_t> verts2collapse;
  DeviceBuffer<uint8_t> edges2state;  // conflict passes: 0 undecided, 1 in, 2 out
  // admissible() over every marked edge (the atomic-min conflicts), and conflict pass 1's winners
  DeviceBuffer<uint32_t> edges_are_admissible, edges_pass1;
  // in_place: the matching selection applied the collapses (collapse_and_compact only compacts),
  // and tets_are_dead holds the tets they removed.
  DeviceBuffer<uint8_t> tets_are_dead;
  bool in_place = false;
  // Under a boundary error bound (StageParams::bound): per edge taken, the bound its survivor
  // takes (-1: S unchanged), from the selection's test (bound.hpp).
  DeviceBuffer<double> edges2eps;
};

}  // namespace tc::collapse_detail
