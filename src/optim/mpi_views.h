// The views of a reconstruction spread over MPI ranks: `mpirun -np N sft reconstruct ...`
// (docs/cli.md, "Several processes"; the protocol and its decisions: docs/design-notes.md,
// 2026-11-27).
//
// Rank 0 runs the schedule and Ceres exactly as a single process does; its render cache hands
// the jobs of every evaluation (view_jobs.h) to an MpiViewRunner. Ranks 1..N−1 load the dataset
// from rank 0's path and serve jobs (ServeViews) until rank 0 stops them. One evaluation:
//   1. rank 0 broadcasts a header, the parts of the RenderState that changed since the last
//      evaluation (scene, positions, material, settings, a fitted environment's texels) and the
//      job list with each job's rank; adjoint weights go to the job's rank alone;
//   2. every rank renders its jobs in job order (the jobs are cut into contiguous runs, rank 0's
//      first, balanced by each (view, pass)'s last measured render time and each rank's last
//      measured speed);
//   3. rank 0 consumes its own results, then receives the others' in job order, so the render
//      cache stores and sums (adjoint gradients) in the order a single process does: results are
//      identical to the bit for any rank count.
// Faults: a rank that dies or stops answering is a fault rank 0 notices itself (see
// MpiViewRunner); it then renders every remaining job in its own process, so that the current
// evaluation completes with the same results, and reports failed() for the caller to stop, write
// its checkpoint and end every rank (MpiSession::Abort).
// Built without MPI (CMake option SFT_MPI off), Launched() is false and nothing here is used.
// A process not started by mpirun never initializes MPI.
#ifndef SFT_OPTIM_MPI_VIEWS_H_
#define SFT_OPTIM_MPI_VIEWS_H_

#include <atomic>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"
#include "src/optim/view_jobs.h"

namespace sft {

// Where rank 0's time in spread evaluations went (seconds, summed over evaluations), and the
// bytes it moved.
struct MpiViewStats {
  int ranks = 1;
  int64_t evaluations = 0;    // runs of jobs spread over the ranks.
  int64_t remote_jobs = 0;    // jobs rendered on other ranks.
  double broadcast = 0.0;     // sending the header, state, job list and adjoint weights.
  double local_render = 0.0;  // rendering rank 0's own jobs (storing them not included).
  double imbalance = 0.0;     // waiting for a rank that was still rendering when rank 0 was done.
  // The other side of the imbalance: per evaluation, the mean over the other ranks of the time
  // they sat idle after their last result while rank 0 was still on its own share.
  double worker_idle = 0.0;
  double gather = 0.0;          // the rest of the wait: receiving and decoding the results.
  int64_t broadcast_bytes = 0;  // per receiving rank.
  int64_t gather_bytes = 0;     // results received.
};

// The stats as JSON (metrics.json's and `sft bench reconstruct --json`'s "mpi" entry): ranks,
// evaluations, remote_jobs, seconds {broadcast, local_render, imbalance, worker_idle, gather},
// broadcast_bytes, gather_bytes.
nlohmann::json MpiViewStatsJson(const MpiViewStats& stats);

// The MPI process group of this run.
class MpiSession {
 public:
  // True when sft was built with MPI and this process was started by an MPI launcher (mpirun,
  // mpiexec: their environment variables). A process started without one never calls MPI.
  static bool Launched();
  // Initializes MPI (thread level funneled: only the main thread calls MPI).
  static Status Start(std::unique_ptr<MpiSession>* session);
  ~MpiSession();  // MPI_Finalize.

  int rank() const { return rank_; }
  int size() const { return size_; }

  // Rank 0: the first rank known to be dead, or -1. Known only for ranks that run on this
  // machine (same boot and PID namespace): their process is gone (exited, killed). Ranks
  // elsewhere are caught by the timeout or the launcher's SIGTERM (MpiViewRunner).
  int DeadRank() const;
  // Ends every rank at once (MPI_Abort). After a fault: the dead rank cannot be released, and
  // MPI_Finalize would wait for it.
  [[noreturn]] void Abort(int code) const;

 private:
  MpiSession() = default;
  int rank_ = 0;
  int size_ = 1;
  std::vector<int64_t> pids_;  // rank 0: every rank's process id; 0 when on another machine.
};

// The ranks' agreement before a run; every rank calls it once. Rank 0 passes `own` (its status
// so far: an error stops every rank), the dataset path its workers load and the smallest number of
// views any stage fits (more ranks than that is an error), and the lights it estimates beside
// unknown lighting (EstimatedLights of src/optim/fitted_environment.h). Workers read the dataset
// from that path into *dataset, add those lights as rank 0 did, and report. Every rank returns
// the same verdict: OK, or one error line naming the rank and its reason ("rank 1: ...").
Status MpiHandshake(const MpiSession& session, const Status& own, const std::string& dataset_path,
                    int fitted_views, Dataset* dataset,
                    const std::vector<LightSpec>& estimated_lights = {});

// Rank 0's ViewRunner. Stop() (or the destructor) releases the workers.
//
// A fault is any of: a rank on this machine whose process is gone (MpiSession::DeadRank, checked
// every 0.1 s of every wait), a wait for another rank longer than `timeout_seconds` (> 0), or
// `*terminating` set (the caller's SIGTERM handler: Open MPI's launcher sends SIGTERM to every
// rank when another one died, one odls_base_sigkill_timeout after the death, and SIGKILL one
// more later). From then on the runner makes no MPI call: it renders the rest of the current
// evaluation and every later one with `local` (identical results) and failed() is true.
class MpiViewRunner : public ViewRunner {
 public:
  MpiViewRunner(const MpiSession& session, double timeout_seconds,
                const std::atomic<bool>* terminating = nullptr);
  ~MpiViewRunner() override;
  void Run(const RenderState& state, const std::vector<ViewJob>& jobs, const LocalRender& local,
           const Consume& consume) override;
  // After a fault, ends every rank (the fault in one log line first; callers that print their
  // own line call MpiSession::Abort before).
  void Stop();
  // Whether a fault happened (also when *terminating was set since the last wait).
  bool failed();
  // The fault in words ("rank 1 stopped answering (died or was killed)"); "" without one.
  const std::string& failure() const { return failure_; }
  const MpiViewStats& stats() const { return stats_; }

 private:
  // The rank of every job: contiguous runs, rank 0's first, balanced by the measured costs
  // (*cost: each job's) and the ranks' measured speeds.
  std::vector<int> Assign(const RenderState& state, const std::vector<ViewJob>& jobs,
                          std::vector<double>* cost) const;
  // Sends the header and the state's changed parts (false on a fault).
  bool BroadcastState(const RenderState& state, int64_t header[]);
  // Called while rank 0 has waited `waited` seconds for `rank` (-1: any rank, a broadcast):
  // false on a fault, which failure_ then names.
  bool Healthy(int rank, double waited);

  const MpiSession& session_;
  int size_ = 1;
  double timeout_ = 3600.0;
  const std::atomic<bool>* terminating_ = nullptr;
  std::string failure_;
  bool stopped_ = false;
  MpiViewStats stats_;
  // The state parts (serialized) the workers hold: only changed parts are sent.
  std::vector<std::vector<char>> sent_parts_;
  // Last render seconds per (dataset view, pass), for the balance.
  std::map<std::pair<int, int>, double> cost_;
  // Per rank: its share of the last evaluation's cost over the seconds it took (rank 0's
  // includes storing the results it rendered), so that a rank that stores results or shares its
  // cores gets less. 1 before any measurement.
  std::vector<double> speed_;
};

// A worker's serve loop: renders its jobs of every evaluation until rank 0 stops it.
// Test hook (tests/apps/reconstruct_mpi_test.cc only): with the environment variable
// SFT_TEST_MPI_DIE_AFTER_JOBS=N, the worker kills itself (SIGKILL) after sending N results.
Status ServeViews(const MpiSession& session, const Dataset& dataset);

}  // namespace sft

#endif  // SFT_OPTIM_MPI_VIEWS_H_
