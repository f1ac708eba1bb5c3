// Programs compiled from source on worker threads, each with an OpenCL context of its own on
// the caller's device, handed back as binaries.
//
// Why: a first run on a new machine, driver or cache compiles seconds of kernels, and PoCL
// compiles one program or kernel at a time in a process, under one lock for the whole process:
// other processes are the only way to put a second core to it. So each worker thread, when a
// compile helper is set (set_compile_helper: the command line tool names itself), feeds a helper
// process of its own (run_compile_helper) over a socket; without one it compiles in an OpenCL
// context of its own (which a GPU driver may run side by side). A worker asks its program for its
// binary, which makes PoCL compile every kernel of the program (a binary holds their machine
// code), so the caller's context loads it and compiles nothing at its launches. The caller queues
// the programs a run will use (prefetch) and takes each when it needs it, ahead of the queue if
// no worker has begun it. Workers start with the first job and end, with their helper or
// context, when the queue is empty.
#pragma once

#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tetcollapse/device.hpp"

namespace tc::device_detail {

class CompilePool {
 public:
  struct Job {
    std::string source, options;
    std::string cache_dir, cache_key;  // where the binary is stored (ProgramCache)
  };

  // At most `workers` threads (at least one).
  CompilePool(cl::Device device, int device_index, unsigned workers);
  CompilePool(const CompilePool&) = delete;
  CompilePool& operator=(const CompilePool&) = delete;
  // Drops the queued jobs and waits for those under way.
  ~CompilePool();

  // Queues the job behind those queued before, once per key.
  void prefetch(const std::string& key, Job job);
  // Whether `key` was queued and not taken yet.
  bool has(const std::string& key);
  // The binary of `key`, the job queued first if it was not, and moved to the front if no worker
  // has begun it. Empty when the build failed or the driver returned no binary: the caller then
  // builds from source itself (and gets the build log).
  std::vector<unsigned char> take(const std::string& key, Job job);

 private:
  enum class State { Queued, Running, Done };
  struct Entry {
    Job job;
    State state = State::Queued;
    std::vector<unsigned char> binary;
  };
  void enqueue(const std::string& key, Job job, bool front);  // under m_
  void work();

  cl::Device device_;
  int device_index_;
  unsigned max_workers_;
  unsigned live_workers_ = 0;
  bool stop_ = false;
  std::mutex m_;
  std::condition_variable changed_;  // a job queued, done, or a worker ended
  std::deque<std::string> queue_;
  std::map<std::string, Entry> entries_;
  std::vector<std::thread> threads_;
  std::vector<int> helpers_;  // the helpers' process ids, killed by the destructor
};

// The helper's side of the socket on its standard input: requests are the job's four strings
// (each a 64-bit length and its bytes), the answer the binary (a length and its bytes, 0 when it
// failed); the helper ends at the end of its input.
int serve_compile_requests(const cl::Device& device);

}  // namespace tc::device_detail
