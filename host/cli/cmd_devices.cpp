#include <iomanip>
#include <iostream>

#include "cli/common.hpp"
#include "json.hpp"
#include "tetcollapse/device.hpp"

namespace tc::cli {

void register_devices(CLI::App& app, int& exit_code) {
  auto json = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("devices", "List every OpenCL platform and device");
  cmd->add_flag("--json", *json, "Print one JSON object instead of text");
  cmd->callback([json, &exit_code] {
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
