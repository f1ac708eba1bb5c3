// The improvement phase's options and reports, shared by `tetcollapse improve` and the
// coarsening command (which ends with the phase unless --no-improve).
#pragma once

#include <CLI/CLI.hpp>

#include "json.hpp"
#include "tetcollapse/improve.hpp"

namespace tc::cli {

struct ImproveCli {
  ImproveOptions opt;
  bool no_flips = false, no_smoothing = false, no_splits = false, no_collapse = false, no_harmonic = false;
};
void add_improve_options(CLI::App& cmd, ImproveCli& c);
// The options the flags give, with progress lines on stderr unless quiet.
const ImproveOptions& improve_options(ImproveCli& c, bool quiet);
// Runs the phase with progress lines on stderr unless quiet.
// With a context, the relocation runs on its device (tc::improve's overloads).
ImproveReport run_improve(Mesh& mesh, ImproveCli& c, bool quiet, Context* ctx);
void write_quality(JsonWriter& w, std::string_view key, const QualitySummary& q);
void write_improve(JsonWriter& w, const ImproveReport& r);
// "min 4.8, median 41.2 degrees, 52 below 10, 160 below 13"
std::string quality_line(const QualitySummary& q);

}  // namespace tc::cli
