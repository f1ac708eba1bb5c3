// What a process's resident memory is before it holds any mesh: the OpenCL runtime alone,
// through its C API and none of the project's code (docs/scale.md: the fixed cost of each
// tetcollapse-mpi rank).
//
//     build/bench/bench_runtime_memory
//
// Prints the resident set (VmRSS, and of it the pages of files, mostly the runtime's libraries,
// and the memory allocated) after each step: start, the platform found, a context, one small
// program built (from the runtime's kernel cache when it was built before: run it twice).
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace {

long status_kb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.compare(0, std::strlen(key), key) == 0) return std::stol(line.substr(std::strlen(key) + 1));
  return -1;
}

void row(const char* step) {
  std::printf("%-36s %8.1f %8.1f %8.1f\n", step, status_kb("VmRSS") / 1024.0, status_kb("RssFile") / 1024.0,
              status_kb("RssAnon") / 1024.0);
}

}  // namespace

int main() {
  std::printf("%-36s %8s %8s %8s\n", "resident after (MB)", "total", "files", "alloc");
  row("start");
  cl_platform_id platform;
  cl_uint n = 0;
  if (clGetPlatformIDs(1, &platform, &n) != CL_SUCCESS || n == 0) {
    std::fprintf(stderr, "bench_runtime_memory: no OpenCL platform\n");
    return 3;
  }
  row("clGetPlatformIDs");
  cl_device_id device;
  if (clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, nullptr) != CL_SUCCESS) return 3;
  cl_int err = 0;
  cl_context ctx = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
  if (err != CL_SUCCESS) return 3;
  row("clCreateContext");
  const char* src = "kernel void add_one(global int* a) { a[get_global_id(0)] += 1; }";
  cl_program prog = clCreateProgramWithSource(ctx, 1, &src, nullptr, &err);
  if (err != CL_SUCCESS || clBuildProgram(prog, 1, &device, "", nullptr, nullptr) != CL_SUCCESS) return 3;
  cl_kernel k = clCreateKernel(prog, "add_one", &err);
  if (err != CL_SUCCESS) return 3;
  row("clBuildProgram, clCreateKernel");
  std::printf("%-36s %8.1f\n", "peak (VmHWM)", status_kb("VmHWM") / 1024.0);
  clReleaseKernel(k);
  clReleaseProgram(prog);
  clReleaseContext(ctx);
  return 0;
}
