// tetcollapse-mpi: coarsens a tetrahedral mesh past one device or machine. Run under mpirun;
// every rank parses the same command line, only rank 0 prints usage and help.
#include <mpi.h>

#include <iostream>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "driver.hpp"

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Large blocks mapped apart, and given back when freed: glibc raises its mmap threshold after
  // the first large blocks are freed (the cut's graph, the parts sent away), after which the
  // part's arrays come from the heap between blocks that stay, and rank 0's peak held both.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  CLI::App app{
      "tetcollapse-mpi " TETCOLLAPSE_VERSION
      ": coarsen a tetrahedral mesh on several MPI ranks, each with its own OpenCL device context.\n"
      "  mpirun -n N tetcollapse-mpi IN OUT [options]\n"
      "Rank 0 reads IN and cuts it with METIS into N parts (tets adjacent across faces); each rank\n"
      "coarsens and improves its part with the vertices on faces shared with another part frozen,\n"
      "so the parts stay conforming; rank 0 gathers them and cuts again elsewhere, so the frozen\n"
      "faces are coarsened in the next round, until a round removes fewer than --round-threshold\n"
      "of its tets or after --rounds rounds; rank 0 writes OUT. The same output for the same\n"
      "input, options and number of ranks.\n"
      "Exit codes: 0 ok, 1 failed --check, 2 bad input or usage, 3 device error, 4 output not written,\n"
      "5 internal error."};
  app.set_version_flag("--version", "tetcollapse-mpi " TETCOLLAPSE_VERSION);
  tc::mpi::Options options;
  tc::mpi::add_options(app, options);
  int code = 0;
  try {
    app.parse(argc, argv);
    code = tc::mpi::run(options, MPI_COMM_WORLD);
  } catch (const CLI::ParseError& e) {
    // every rank parsed the same arguments: all stop, rank 0 says why
    if (rank == 0) code = app.exit(e);
    else code = e.get_exit_code();
    code = code == 0 ? 0 : tc::cli::kBadInput;
  }
  MPI_Finalize();
  return code;
}
