#include "device/compile_pool.hpp"

#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstring>

#include "device/program_cache.hpp"

extern char** environ;

namespace tc {

namespace {
std::mutex g_helper_mutex;
std::vector<std::string> g_helper;  // set_compile_helper's command
}  // namespace

void set_compile_helper(std::vector<std::string> argv) {
  std::lock_guard<std::mutex> lock(g_helper_mutex);
  g_helper = std::move(argv);
}

}  // namespace tc

namespace tc::device_detail {

namespace {

// Every failure is an empty binary: the caller's own build reports it.
std::vector<unsigned char> compile(cl::Context& ctx, const cl::Device& device, const CompilePool::Job& job) {
  try {
    cl::Program prog(ctx, job.source);
    prog.build({device}, job.options.c_str());
    auto bins = prog.getInfo<CL_PROGRAM_BINARIES>();
    if (bins.size() != 1 || bins[0].empty()) return {};
    ProgramCache(job.cache_dir, job.cache_key).store(bins[0]);
    return std::move(bins[0]);
  } catch (const cl::Error&) {
    return {};
  }
}

bool send_all(int fd, const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t k = ::send(fd, p, n, MSG_NOSIGNAL);  // a helper gone is an error, not SIGPIPE
    if (k <= 0) return false;
    p += k, n -= size_t(k);
  }
  return true;
}

bool recv_all(int fd, void* data, size_t n) {
  char* p = static_cast<char*>(data);
  while (n > 0) {
    const ssize_t k = ::read(fd, p, n);
    if (k <= 0) return false;
    p += k, n -= size_t(k);
  }
  return true;
}

bool send_block(int fd, const void* data, uint64_t n) { return send_all(fd, &n, 8) && send_all(fd, data, n); }

template <class V>
bool recv_block(int fd, V& out) {
  uint64_t n = 0;
  if (!recv_all(fd, &n, 8) || n > (uint64_t(1) << 32)) return false;
  out.resize(n);
  return recv_all(fd, out.data(), n);
}

// One helper process: its id and our end of its socket (-1 / -1 when none could be started).
struct Helper {
  pid_t pid = -1;
  int fd = -1;
};

Helper spawn_helper(int device_index) {
  std::vector<std::string> argv;
  {
    std::lock_guard<std::mutex> lock(g_helper_mutex);
    argv = g_helper;
  }
  if (argv.empty()) return {};
  argv.push_back(std::to_string(device_index));
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) return {};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, sv[1], 0);  // the helper's standard input is its socket
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  ::close(sv[1]);
  if (rc != 0) {
    ::close(sv[0]);
    return {};
  }
  return {pid, sv[0]};
}

void end_helper(Helper& h) {
  if (h.fd >= 0) ::close(h.fd);  // the helper reads the end of its input and exits
  if (h.pid > 0) ::waitpid(h.pid, nullptr, 0);
  h = {};
}

// The binary, or nothing with *failed set when the helper is gone (the caller ends it).
std::vector<unsigned char> compile_in(Helper& h, const CompilePool::Job& job, bool* failed) {
  std::vector<unsigned char> bin;
  *failed = !(send_block(h.fd, job.source.data(), job.source.size()) &&
              send_block(h.fd, job.options.data(), job.options.size()) &&
              send_block(h.fd, job.cache_dir.data(), job.cache_dir.size()) &&
              send_block(h.fd, job.cache_key.data(), job.cache_key.size()) && recv_block(h.fd, bin));
  if (*failed) bin.clear();
  return bin;
}

}  // namespace

int serve_compile_requests(const cl::Device& device) {
  cl::Context ctx(device);
  for (;;) {
    CompilePool::Job job;
    if (!recv_block(0, job.source)) return 0;  // the end of the input: the parent is done
    if (!recv_block(0, job.options) || !recv_block(0, job.cache_dir) || !recv_block(0, job.cache_key)) return 1;
    const std::vector<unsigned char> bin = compile(ctx, device, job);
    if (!send_block(0, bin.data(), bin.size())) return 1;
  }
}

CompilePool::CompilePool(cl::Device device, int device_index, unsigned workers)
    : device_(std::move(device)), device_index_(device_index), max_workers_(std::max(1u, workers)) {}

CompilePool::~CompilePool() {
  std::unique_lock<std::mutex> lock(m_);
  stop_ = true;
  queue_.clear();
  for (int pid : helpers_) ::kill(pid, SIGKILL);  // a compile under way is of no use any more
  changed_.notify_all();
  changed_.wait(lock, [&] { return live_workers_ == 0; });
  lock.unlock();
  for (std::thread& t : threads_) t.join();
}

void CompilePool::enqueue(const std::string& key, Job job, bool front) {
  auto it = entries_.find(key);
  if (it == entries_.end()) {
    entries_.emplace(key, Entry{std::move(job), State::Queued, {}});
    if (front)
      queue_.push_front(key);
    else
      queue_.push_back(key);
  } else if (front && it->second.state == State::Queued) {
    queue_.erase(std::find(queue_.begin(), queue_.end(), key));
    queue_.push_front(key);
  } else {
    return;
  }
  if (live_workers_ < max_workers_) {
    ++live_workers_;
    try {
      threads_.emplace_back([this] { work(); });
    } catch (...) {
      --live_workers_;  // no thread: take() leaves the build to its caller when none runs
    }
  }
  changed_.notify_all();
}

void CompilePool::prefetch(const std::string& key, Job job) {
  std::lock_guard<std::mutex> lock(m_);
  enqueue(key, std::move(job), false);
}

bool CompilePool::has(const std::string& key) {
  std::lock_guard<std::mutex> lock(m_);
  return entries_.count(key) > 0;
}

std::vector<unsigned char> CompilePool::take(const std::string& key, Job job) {
  std::unique_lock<std::mutex> lock(m_);
  enqueue(key, std::move(job), true);
  if (live_workers_ == 0 && entries_.at(key).state == State::Queued) {  // no worker could start
    queue_.erase(std::find(queue_.begin(), queue_.end(), key));
    entries_.erase(key);
    return {};
  }
  changed_.wait(lock, [&] { return entries_.at(key).state == State::Done; });
  std::vector<unsigned char> out = std::move(entries_.at(key).binary);
  entries_.erase(key);
  return out;
}

void CompilePool::work() {
  Helper helper = spawn_helper(device_index_);
  cl::Context ctx;  // without a helper
  bool have_ctx = false;
  std::unique_lock<std::mutex> lock(m_);
  if (helper.pid > 0) helpers_.push_back(helper.pid);
  while (!stop_ && !queue_.empty()) {
    const std::string key = queue_.front();
    queue_.pop_front();
    Entry& e = entries_.at(key);  // std::map: the reference outlives other insertions
    e.state = State::Running;
    lock.unlock();
    std::vector<unsigned char> binary;
    if (helper.fd >= 0) {
      bool failed = false;
      binary = compile_in(helper, e.job, &failed);  // on failure the caller builds it (the next jobs are ours)
      if (failed) {
        // out of the destructor's list before it is reaped: its pid may be reused after
        lock.lock();
        helpers_.erase(std::find(helpers_.begin(), helpers_.end(), helper.pid));
        lock.unlock();
        end_helper(helper);
      }
    } else {
      try {  // no helper (none set, none started, or one failed): in this process
        if (!have_ctx) ctx = cl::Context(device_), have_ctx = true;
        binary = compile(ctx, device_, e.job);
      } catch (const cl::Error&) {
      }
    }
    lock.lock();
    e.binary = std::move(binary);
    e.state = State::Done;
    changed_.notify_all();
  }
  // no more jobs for this worker from here: one queued now starts another (the destructor joins
  // this thread, which waits for its helper to end)
  --live_workers_;
  if (helper.pid > 0) helpers_.erase(std::find(helpers_.begin(), helpers_.end(), helper.pid));
  changed_.notify_all();
  lock.unlock();
  end_helper(helper);
}

}  // namespace tc::device_detail
