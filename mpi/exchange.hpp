// Moving parts between ranks: a part is packed into one byte buffer (sizes first, then the
// arrays as they are in memory: every rank runs the same build on the same kind of machine) and
// sent point to point, in pieces below MPI's int count limit.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <vector>

#include "part.hpp"

namespace tc::mpi {

std::vector<char> pack(const Part& part);
Part unpack(const std::vector<char>& bytes);  // throws std::runtime_error on a short buffer

// Blocking (sleeping while they wait, see wait_politely); the receiver must call recv_part with
// the sender's rank.
void send_part(const Part& part, int dest, MPI_Comm comm);
Part recv_part(int source, MPI_Comm comm);

}  // namespace tc::mpi
