#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace tc {

// Bad input: a file that cannot be read as the format it claims, or data that makes no
// mesh. what() is one line: "FILE:LINE: reason" for text, "FILE: byte OFFSET: reason" for
// binary data, "FILE: reason" when no position applies. The CLI exits with code 2.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& reason);
  InputError(const std::string& file, int64_t line, const std::string& reason);
  static InputError at_byte(const std::string& file, int64_t offset, const std::string& reason);

  const std::string& file() const { return file_; }
  int64_t line() const { return line_; }          // -1 when not known
  int64_t byte_offset() const { return offset_; }  // -1 when not known
  const std::string& reason() const { return reason_; }

 private:
  InputError(const std::string& file, int64_t line, int64_t offset, const std::string& reason);
  std::string file_;
  int64_t line_ = -1;
  int64_t offset_ = -1;
  std::string reason_;
};

// Failure to write a result (disk full, permission denied). The target is left untouched.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An OpenCL or device failure. CLI exit code 3.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tc
