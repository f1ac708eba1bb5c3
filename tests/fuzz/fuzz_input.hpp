// How a fuzz input becomes the file(s) a reader opens. Shared by the libFuzzer harnesses
// (tests/fuzz/fuzz_*.cpp) and the regression test (tests/io/test_fuzz_regressions.cpp), so a
// crasher saved by libFuzzer replays exactly as the fuzzer ran it.
//
// The readers take paths (and Medit/TetGen read several files), so one input holds every
// file the reader opens, in a fixed order, separated by kPartSeparator:
//   gmsh:   x.msh
//   medit:  x.mesh [ SEP x.sol ]          (binary or ASCII is told from the content)
//   vtk:    x.vtk
//   vtu:    x.vtu
//   tetgen: x.node SEP x.ele [ SEP x.face ]
// A part that is missing is a file that does not exist (x.sol, x.face are optional;
// a missing x.ele is an error the reader must report).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "tetcollapse/io.hpp"

namespace tc::fuzz {

// A line no mesh format uses; the fuzzer dictionaries contain it so mutations can add or
// remove parts.
inline constexpr std::string_view kPartSeparator = "\n#~~next-file~~#\n";

inline std::vector<std::string_view> split_parts(std::string_view data, size_t max_parts) {
  std::vector<std::string_view> parts;
  while (parts.size() + 1 < max_parts) {
    const size_t at = data.find(kPartSeparator);
    if (at == std::string_view::npos) break;
    parts.push_back(data.substr(0, at));
    data.remove_prefix(at + kPartSeparator.size());
  }
  parts.push_back(data);
  return parts;
}

struct Layout {
  Format format;
  std::vector<const char*> names;  // file names of the parts, in order
};

inline Layout layout_of(Format f) {
  switch (f) {
    case Format::Gmsh: return {f, {"x.msh"}};
    case Format::Medit: return {f, {"x.mesh", "x.sol"}};
    case Format::Vtk: return {f, {"x.vtk"}};
    case Format::Vtu: return {f, {"x.vtu"}};
    case Format::TetGen: return {f, {"x.node", "x.ele", "x.face"}};
    case Format::Auto: break;
  }
  return {f, {}};
}

inline void write_bytes(const std::filesystem::path& path, std::string_view bytes) {
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (!out) std::abort();  // the harness itself failed, not the reader
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), out) != bytes.size()) std::abort();
  std::fclose(out);
}

// Writes the parts of `data` into `dir` (removing the files of absent parts) and returns
// the path to give read_mesh.
inline std::string materialize(const std::filesystem::path& dir, Format f, std::string_view data) {
  const Layout layout = layout_of(f);
  const std::vector<std::string_view> parts = split_parts(data, layout.names.size());
  for (size_t i = 0; i < layout.names.size(); ++i) {
    const std::filesystem::path p = dir / layout.names[i];
    if (i < parts.size()) {
      write_bytes(p, parts[i]);
    } else {
      std::error_code ec;
      std::filesystem::remove(p, ec);
    }
  }
  return (dir / layout.names[0]).string();
}

// The reading the harnesses exercise: the format's reader, then the structural validation
// and orientation repair of read_mesh (with Fix, so inverted tets do not stop it early).
inline Mesh read_input(const std::string& path, Format f) {
  ReadOptions options;
  options.format = f;
  options.orientation = OrientationPolicy::Fix;
  options.read_sol = true;
  return read_mesh(path, options);
}

}  // namespace tc::fuzz
