// tetcollapse: the command-line tool. Each subcommand lives in its own cmd_*.cpp file; this
// file only wires them together and turns exceptions into the documented exit codes.
#include <cstdlib>
#include <iostream>
#include <string>

#include "cli/common.hpp"

int main(int argc, char** argv) {
  using namespace tc::cli;
  // a first run's kernels compile in helpers, this program started again (tc::set_compile_helper)
  if (argc == 3 && std::string(argv[1]) == kCompileHelperArg) return tc::run_compile_helper(std::atoi(argv[2]));
  tc::set_compile_helper({"/proc/self/exe", kCompileHelperArg});
  CLI::App app{
      "tetcollapse " TETCOLLAPSE_VERSION
      ": coarsen unstructured tetrahedral meshes by massively parallel edge collapse (OpenCL).\n"
      "Exit codes: 0 ok, 1 failed check, 2 bad input or usage, 3 device error, 4 output not written, 5 internal error."};
  app.set_version_flag("--version", "tetcollapse " TETCOLLAPSE_VERSION);
  app.require_subcommand(0, 1);
  int exit_code = kOk;
  register_collapse(app, exit_code);
  register_info(app, exit_code);
  register_convert(app, exit_code);
  register_devices(app, exit_code);
#ifdef TETCOLLAPSE_HAVE_CHECK
  register_check(app, exit_code);
#endif
  register_features(app, exit_code);
  register_improve(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);  // prints help / version / the usage error
    return rc == 0 ? kOk : kBadInput;
  } catch (const tc::InputError& e) {
    std::cerr << "tetcollapse: error: " << e.what() << "\n";
    return kBadInput;
  } catch (const tc::DeviceError& e) {
    std::cerr << "tetcollapse: device error: " << e.what() << "\n";
    return kDeviceError;
  } catch (const tc::OutputError& e) {
    std::cerr << "tetcollapse: cannot write: " << e.what() << "\n";
    return kOutputError;
  } catch (const std::bad_alloc&) {
    std::cerr << "tetcollapse: out of memory\n";
    return 5;
  } catch (const std::exception& e) {
    std::cerr << "tetcollapse: internal error: " << e.what() << "\n";
    return 5;
  }
  return exit_code;
}
