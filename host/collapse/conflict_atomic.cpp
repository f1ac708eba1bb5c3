// Atomic-min conflict detection (CollapseOptions::AtomicMin). PLACEHOLDER being written (issue 6):
// it refuses to run until the implementation lands.
#include <stdexcept>

#include "collapse/stages.hpp"

namespace tc::collapse_detail {

uint32_t conflicts_atomic_min(Context&, DeviceMesh&, Connectivity&, EdgeState&) {
  throw std::invalid_argument("the atomic-min conflict detection is not implemented yet");
}

}  // namespace tc::collapse_detail
