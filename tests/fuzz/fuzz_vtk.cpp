// libFuzzer harness for the Vtk reader (see fuzz_input.hpp for how the input maps to files).
#include "fuzz_harness.hpp"

TC_FUZZ_HARNESS(tc::Format::Vtk)
