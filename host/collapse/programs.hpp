// The device programs a run uses, in the order it first needs them, for Context::prefetch: a
// first run (nothing in the disk cache) compiles them on every core while it waits for the
// first. A program left out is compiled when first used; one too many costs a compile.
#pragma once

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"

namespace tc::collapse_detail {
// Which way collapse() goes: the sequential method on the host (asked for, or under a field
// error bound, whose check reads the input on the host), the device under a boundary error
// bound, or the device alone.
enum class CollapsePath { Host, DeviceBounded, Device };
CollapsePath collapse_path(const CollapseOptions& options);  // collapse.cpp
// The programs of collapse()'s path on the device (none on the host's).
void prefetch_programs(Context& ctx, const CollapseOptions& options);  // collapse.cpp
}

namespace tc::improve_detail {
void prefetch_programs(Context& ctx);  // improve.cpp
}

namespace tc::fields_detail {
// resample_vertex_fields' on the device: the BVH, its sort and scan (device/bvh.cpp).
void prefetch_programs(Context& ctx);
}
