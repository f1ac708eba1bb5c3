#include "agree.hpp"

#include <iostream>
#include <new>
#include <string>

#include "cli/common.hpp"

namespace tc::mpi {

int guarded(int rank, const std::function<void()>& fn) {
  const std::string who = "tetcollapse-mpi: rank " + std::to_string(rank) + ": ";
  try {
    fn();
    return cli::kOk;
  } catch (const CLI::ValidationError& e) {
    if (rank == 0) std::cerr << "tetcollapse-mpi: " << e.what() << "\n";  // every rank saw the same options
    return cli::kBadInput;
  } catch (const InputError& e) {
    std::cerr << who << "error: " << e.what() << "\n";
    return cli::kBadInput;
  } catch (const DeviceError& e) {
    std::cerr << who << "device error: " << e.what() << "\n";
    return cli::kDeviceError;
  } catch (const OutputError& e) {
    std::cerr << who << "cannot write: " << e.what() << "\n";
    return cli::kOutputError;
  } catch (const std::bad_alloc&) {
    std::cerr << who << "out of memory\n";
    return 5;
  } catch (const std::exception& e) {
    std::cerr << who << "internal error: " << e.what() << "\n";
    return 5;
  }
}

int agree(int code, MPI_Comm comm) {
  int worst = 0;
  MPI_Allreduce(&code, &worst, 1, MPI_INT, MPI_MAX, comm);
  return worst;
}

}  // namespace tc::mpi
