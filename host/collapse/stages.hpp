// Every stage of a collapse iteration, for the callers that use them one at a time (the tests,
// the benches). The driver, collapse.cpp, reads them as the paper's Algorithm 1.
#pragma once

#include "collapse/admissible.hpp"
#include "collapse/compact.hpp"
#include "collapse/connectivity.hpp"
#include "collapse/cost.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/params.hpp"
#include "collapse/select_atomic_min.hpp"
#include "collapse/select_greedy.hpp"
#include "collapse/select_matching.hpp"
#include "collapse/select_two_pass.hpp"
#include "collapse/upload.hpp"
#include "collapse/verdict_carry.hpp"
