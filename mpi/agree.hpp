// Errors across ranks: a rank's exception becomes the README's exit code, and every rank learns
// the worst code of any at the next agreement, so that all stop together with the same code
// (and none waits forever for a message a failed rank will not send).
#pragma once

#include <mpi.h>

#include <functional>

namespace tc::mpi {

// Runs fn; an exception becomes an exit code and a line on stderr naming the rank (usage
// errors, which every rank sees alike, are printed by rank 0 only).
int guarded(int rank, const std::function<void()>& fn);
// The largest code of any rank, on every rank (after wait_politely).
int agree(int code, MPI_Comm comm);

// Waits until every rank of comm has called it, sleeping meanwhile: Open MPI's blocking calls
// spin, and while rank 0 reads, cuts or merges alone the spinning ranks took the cores it needs
// (3 ranks on 2 cores: 2 of them). A millisecond of latency per call.
void wait_politely(MPI_Comm comm);
void wait_politely(MPI_Request& request);

}  // namespace tc::mpi
