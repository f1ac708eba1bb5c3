#include <iomanip>
#include <iostream>

#include "cli/common.hpp"
#include "json.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/improve.hpp"

namespace tc::cli {

namespace {
// Runs what a default coarsening runs (the collapse, then the improvement) on a small mesh, so
// that every kernel it uses is compiled and cached: for container images and first contact.
void warm_up(const std::string& spec) {
  const Stopwatch clock;
  std::unique_ptr<Context> ctx = open_device(spec, false);
  Mesh m = make_cube_mesh(10);
  uint64_t x = 88172645463325252ull;  // a fixed jiggle (xorshift), so that the improvement has work
  for (double& c : m.points) {
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    if (c > 0 && c < 1) c += (double(x % 1000) / 1000.0 - 0.5) * 0.04;
  }
  CollapseOptions o;
  o.target_factor = 2;
  Mesh unbounded = m;
  collapse(unbounded, o, *ctx);  // the paper's method (--max-boundary-error 0, the library's default)
  o.max_boundary_error = kDefaultMaxBoundaryError;  // the command's default: its programs' variants
  collapse(m, o, *ctx);
  improve(m, ImproveOptions{}, *ctx);
  std::cerr << "warmed up " << ctx->info().name << " in " << clock.peek() << " s\n";
}
}  // namespace

void register_devices(CLI::App& app, int& exit_code) {
  auto json = std::make_shared<bool>(false);
  auto warm = std::make_shared<bool>(false);
  auto device = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("devices", "List every OpenCL platform and device");
  cmd->add_flag("--json", *json, "Print one JSON object instead of text");
  cmd->add_flag("--warm-up", *warm,
                "Compile and cache the kernels a default run uses on the device (--device), as the\n"
                "first run on a new machine, driver or container image would (seconds), so that later\n"
                "runs start at once");
  cmd->add_option("--device", *device, "With --warm-up: the device (index or name substring)");
  cmd->callback([json, warm, device, &exit_code] {
    if (*warm) {
      warm_up(*device);
      exit_code = kOk;
      return;
    }
    std::vector<DeviceInfo> devs = list_devices();
    std::string chosen;
    try {
      chosen = select_device().name;
    } catch (const DeviceError&) {
    }
    if (*json) {
      JsonWriter w;
      w.begin_object().key("devices").begin_array();
      for (const auto& d : devs) {
        w.begin_object()
            .field("index", d.index)
            .field("platform", d.platform_name)
            .field("name", d.name)
            .field("vendor", d.vendor)
            .field("driver", d.driver_version)
            .field("type", d.type)
            .field("compute_units", static_cast<int64_t>(d.compute_units))
            .field("global_mem_bytes", static_cast<uint64_t>(d.global_mem_bytes))
            .field("local_mem_bytes", static_cast<uint64_t>(d.local_mem_bytes))
            .field("fp64", d.fp64)
            .field("int64_atomics", d.int64_atomics_extended)
            .end_object();
      }
      w.end_array().field("default", chosen).end_object();
      std::cout << w.str() << "\n";
    } else {
      for (const auto& d : devs) {
        std::cout << "[" << d.index << "] " << d.name << (d.name == chosen ? "  (default)" : "") << "\n"
                  << "    platform: " << d.platform_name << " (" << d.platform_version << ")\n"
                  << "    vendor: " << d.vendor << ", driver " << d.driver_version << ", type " << d.type << "\n"
                  << "    compute units: " << d.compute_units << ", global memory: " << std::fixed
                  << std::setprecision(1) << d.global_mem_bytes / 1073741824.0 << " GiB, local memory: "
                  << d.local_mem_bytes / 1024 << " KiB\n"
                  << "    fp64: " << (d.fp64 ? "yes" : "no (cannot be used)")
                  << ", 64-bit atomics: " << (d.int64_atomics_extended ? "yes" : "no") << "\n";
      }
    }
    exit_code = kOk;
  });
}

}  // namespace tc::cli
