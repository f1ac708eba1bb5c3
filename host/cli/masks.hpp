// --region and --labels: the vertices a run may change, for tetcollapse and tetcollapse-mpi
// alike (the same option names, help and rules in both tools).
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::cli {

inline constexpr const char* kRegionHelp =
    "Only collapse edges inside a region: box:X0,Y0,Z0,X1,Y1,Z1 or sphere:X,Y,Z,R";
inline constexpr const char* kLabelsHelp = "Only coarsen inside these primary labels, e.g. 1,3";

// Comma-separated numbers; CLI::ValidationError naming `what` on anything else.
std::vector<double> parse_numbers(const std::string& s, const std::string& what);
// --region box:X0,Y0,Z0,X1,Y1,Z1 | sphere:X,Y,Z,R -> per-vertex mask (1 inside).
std::vector<uint8_t> region_mask(const Mesh& m, const std::string& spec);
// --labels A,B,...: a vertex is selected when every tet around it has a selected primary label,
// so material interfaces to unselected labels stay where they are. InputError without labels.
std::vector<uint8_t> label_mask(const Mesh& m, const std::string& spec);
// InputError naming --labels when m has none (label_mask's own check, for a caller that only
// wants to fail early).
void require_labels(const Mesh& m);
// Both, as one mask (a vertex selected by each given); empty when neither is given.
std::vector<uint8_t> region_and_label_mask(const Mesh& m, const std::string& region, const std::string& labels);
// The two specs' syntax alone, before any mesh is read (CLI::ValidationError).
void check_region_and_labels(const std::string& region, const std::string& labels);
// mask &= more (an empty mask selects everything).
void combine(std::vector<uint8_t>& mask, const std::vector<uint8_t>& more);

}  // namespace tc::cli
