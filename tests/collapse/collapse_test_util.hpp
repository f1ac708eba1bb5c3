// Helpers shared by the collapse tests (tests/support holds those of every test executable,
// some of which do not build against the OpenCL bindings that tetcollapse/collapse.hpp brings).
#pragma once

#include <algorithm>

#include "tetcollapse/collapse.hpp"

namespace tc::test {

// How many of a run's iterations ran on the host (the host tail: IterationStats::on_host).
inline int count_on_host(const CollapseReport& r) {
  return int(std::count_if(r.iterations.begin(), r.iterations.end(), [](const IterationStats& s) { return s.on_host; }));
}

}  // namespace tc::test
