// The body every libFuzzer harness shares: write the input as the reader's file(s) in a
// private temporary folder (in /dev/shm when there is one, so no disk I/O per run), read
// it, and accept tc::InputError as the expected answer to bad input. Any other exception
// escapes and libFuzzer reports it ("deadly signal" after std::terminate), as it reports
// crashes, sanitizer errors, timeouts and out-of-memory.
#pragma once

#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fuzz_input.hpp"

namespace tc::fuzz {

class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    std::string base = std::filesystem::is_directory("/dev/shm", ec) ? "/dev/shm" : std::filesystem::temp_directory_path().string();
    std::string templ = base + "/tc-fuzz-XXXXXX";
    if (!mkdtemp(templ.data())) std::abort();
    path_ = templ;
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A mesh that read_mesh accepted must be consistent (it validated it): every size the
// mesh model promises is checked here, and every index is used, so that a reader returning
// inconsistent arrays is a finding (abort, or a sanitizer report) rather than silence.
inline void check_accepted(const Mesh& m) {
  auto require = [](bool ok, const char* what) {
    if (!ok) {
      std::fprintf(stderr, "tc fuzz: accepted mesh is inconsistent: %s\n", what);
      std::abort();
    }
  };
  const size_t nv = static_cast<size_t>(m.num_vertices()), nt = static_cast<size_t>(m.num_tets());
  require(m.points.size() % 3 == 0 && m.tets.size() % 4 == 0, "points/tets not whole records");
  require(m.tris.size() % 3 == 0 && m.tri_tags.size() == m.tris.size() / 3, "triangles/tags");
  require(m.edges.size() % 2 == 0 && m.edge_tags.size() == m.edges.size() / 2, "edges/tags");
  for (const Labels& l : m.tet_labels) require(l.values.size() == nt, "tet label size");
  for (const Field& fd : m.vertex_fields) require(fd.values.size() == nv * static_cast<size_t>(fd.components), "vertex field size");
  for (const Field& fd : m.tet_fields) require(fd.values.size() == nt * static_cast<size_t>(fd.components), "tet field size");
  volatile double sink = 0;
  for (int32_t v : m.tets) {
    require(v >= 0 && static_cast<size_t>(v) < nv, "tet vertex index out of range");
    sink = sink + m.points[3 * static_cast<size_t>(v)];
  }
}

// TC_FUZZ_ROUNDTRIP=1: every accepted mesh is also written in its own format (encoding
// and Gmsh version picked from the input size) and read back, which must give the same
// vertices and tet count. Finds writer failures on unusual but accepted data.
inline bool roundtrip() {
  static const bool v = std::getenv("TC_FUZZ_ROUNDTRIP") != nullptr;
  return v;
}

inline void check_roundtrip(const std::filesystem::path& dir, Format f, const Mesh& m, size_t size) {
  WriteOptions o;
  o.format = f;
  o.binary = size % 2 == 0;
  o.gmsh_version = size % 4 < 2 ? 41 : 22;
  o.vtu_encoding = size % 3 == 0 ? WriteOptions::VtuEncoding::Ascii
                 : size % 3 == 1 ? WriteOptions::VtuEncoding::Base64 : WriteOptions::VtuEncoding::Appended;
  const char* name = f == Format::Gmsh ? "rt.msh" : f == Format::Medit ? (o.binary ? "rt.meshb" : "rt.mesh")
                   : f == Format::Vtk ? "rt.vtk" : f == Format::Vtu ? "rt.vtu" : "rt.node";
  const std::string path = (dir / name).string();
  write_mesh(path, m, o);  // an OutputError escapes: a finding
  Mesh back;
  try {
    back = read_input(path, f);
  } catch (const InputError& e) {
    std::fprintf(stderr, "tc fuzz: the writer's output does not read back: %s\n", e.what());
    std::abort();
  }
  if (back.num_tets() != m.num_tets() || back.points != m.points) {
    std::fprintf(stderr, "tc fuzz: round trip changed the mesh (%lld -> %lld tets, %lld -> %lld vertices)\n",
                 (long long)m.num_tets(), (long long)back.num_tets(), (long long)m.num_vertices(),
                 (long long)back.num_vertices());
    std::abort();
  }
  std::error_code ec;
  for (const char* junk : {"rt.msh", "rt.mesh", "rt.meshb", "rt.sol", "rt.solb", "rt.vtk", "rt.vtu", "rt.node", "rt.ele", "rt.face"})
    std::filesystem::remove(dir / junk, ec);
}

// TC_FUZZ_VERBOSE=1 prints each input's InputError (to see why a seed is rejected).
inline bool verbose() {
  static const bool v = std::getenv("TC_FUZZ_VERBOSE") != nullptr;
  return v;
}

inline int run_one(Format f, const uint8_t* data, size_t size) {
  static ScratchDir dir;  // one per process, removed at exit
  const std::string path =
      materialize(dir.path(), f, std::string_view(reinterpret_cast<const char*>(data), size));
  try {
    const Mesh m = read_input(path, f);
    check_accepted(m);
    if (roundtrip()) check_roundtrip(dir.path(), f, m, size);
  } catch (const InputError& e) {
    // Expected for bad input, except the "internal:" errors of validate_structure, which
    // mean a reader produced inconsistent arrays.
    if (e.reason().rfind("internal:", 0) == 0) {
      std::fprintf(stderr, "tc fuzz: reader produced an inconsistent mesh: %s\n", e.what());
      std::abort();
    }
    if (verbose()) std::fprintf(stderr, "InputError: %s\n", e.what());
  }
  return 0;
}

}  // namespace tc::fuzz

#define TC_FUZZ_HARNESS(FORMAT)                                               \
  extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) { \
    return tc::fuzz::run_one(FORMAT, data, size);                            \
  }
