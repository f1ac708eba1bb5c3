// Wall time of consecutive stages, shared by the collapse driver, the command line and the
// benches: lap() returns the seconds since the previous lap (or the start).
#pragma once

#include <chrono>

namespace tc {

class Stopwatch {
 public:
  Stopwatch() : last_(now()) {}
  double lap() {
    const double t = now(), d = t - last_;
    last_ = t;
    return d;
  }
  // Seconds since the previous lap, without starting a new one.
  double peek() const { return now() - last_; }
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }

 private:
  double last_;
};

}  // namespace tc
