// The sequential CPU method (CollapseOptions::Sequential). PLACEHOLDER being written (issue 6):
// it refuses to run until the implementation lands.
#include <stdexcept>

#include "tetcollapse/collapse.hpp"

namespace tc {

CollapseReport collapse_sequential(Mesh&, const CollapseOptions&) {
  throw std::invalid_argument("the sequential method is not implemented yet");
}

}  // namespace tc
