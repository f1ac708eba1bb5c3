// Named kernel arguments (host/collapse/launch.hpp): every argument set by its parameter's name,
// a scalar converted to the parameter's type, and a mistake refused with the kernel's name.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "collapse/launch.hpp"
#include "test_support.hpp"
#include "tetcollapse/error.hpp"

namespace {

using namespace tc;
using namespace tc::collapse_detail;
using test::error_of;

// conflict_init(uint ne, global const uint* edges_are_admissible, global uchar* edges2state):
// edges2state[e] = edges_are_admissible[e] ? 0 : 2.
const char* kFile = "collapse_conflict.cl";
const char* kName = "conflict_init";

TEST(CollapseLaunch, ArgumentsByNameInAnyOrder) {
  Context ctx;
  DeviceBuffer<uint32_t> adm(ctx, std::vector<uint32_t>{1, 0, 7, 0});
  DeviceBuffer<uint8_t> state(ctx, std::vector<uint8_t>{9, 9, 9, 9});
  const size_t ne = 3;  // a size_t: converted to the parameter's uint
  run(ctx, kFile, kName, ne, arg("edges2state", state), arg("ne", ne), arg("edges_are_admissible", adm));
  EXPECT_EQ(state.download(), (std::vector<uint8_t>{0, 2, 0, 9}));
  // a second kernel object of the same kernel (its parameters read once) sets them again
  run(ctx, kFile, kName, 4, arg("edges_are_admissible", adm), arg("edges2state", state), arg("ne", 4));
  EXPECT_EQ(state.download(), (std::vector<uint8_t>{0, 2, 0, 2}));
}

TEST(CollapseLaunch, MistakesAreRefusedWithTheKernelsName) {
  Context ctx;
  DeviceBuffer<uint32_t> adm(ctx, 4);
  DeviceBuffer<uint8_t> state(ctx, 4);
  std::string e = error_of<DeviceError>([&] { kernel(ctx, kFile, kName).set(arg("flags", adm)); });
  EXPECT_NE(e.find("conflict_init has no parameter 'flags'"), std::string::npos) << e;
  EXPECT_NE(e.find("ne, edges_are_admissible, edges2state"), std::string::npos) << e;
  e = error_of<DeviceError>([&] { kernel(ctx, kFile, kName).set(arg("ne", 4), arg("edges_are_admissible", adm)).launch(ctx, 4); });
  EXPECT_NE(e.find("parameter 'edges2state' is not set"), std::string::npos) << e;
  e = error_of<DeviceError>([&] { kernel(ctx, kFile, kName).set(arg("ne", -1)); });
  EXPECT_NE(e.find("'ne' out of its type's range"), std::string::npos) << e;
  e = error_of<DeviceError>([&] { kernel(ctx, kFile, kName).set(arg("ne", 1.5)); });
  EXPECT_NE(e.find("'ne' takes an integer"), std::string::npos) << e;
  e = error_of<DeviceError>([&] { kernel(ctx, kFile, kName).set(arg("ne", adm)); });
  EXPECT_NE(e.find("'ne' is not a global buffer"), std::string::npos) << e;
  e = error_of<DeviceError>([&] { kernel(ctx, kFile, kName).set(arg("ne", 4), arg("edges_are_admissible", adm), arg("edges2state", state)).launch(ctx, 4); });
  EXPECT_EQ(e, "");
}

}  // namespace
