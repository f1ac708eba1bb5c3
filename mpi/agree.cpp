#include "agree.hpp"

#include <chrono>
#include <iostream>
#include <new>
#include <string>
#include <thread>

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

void wait_politely(MPI_Request& request) {
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void wait_politely(MPI_Comm comm) {
  MPI_Request request;
  MPI_Ibarrier(comm, &request);
  wait_politely(request);
}

int agree(int code, MPI_Comm comm) {
  wait_politely(comm);
  int worst = 0;
  MPI_Allreduce(&code, &worst, 1, MPI_INT, MPI_MAX, comm);
  return worst;
}

}  // namespace tc::mpi
