// The views of a reconstruction spread over MPI ranks: `mpirun -np N sft reconstruct ...`
// (docs/cli.md, "Several processes"; the protocol and its decisions: docs/design-notes.md,
// 2026-11-27).
//
// Rank 0 runs the schedule and Ceres exactly as a single process does; its render cache hands
// the jobs of every evaluation (view_jobs.h) to an MpiViewRunner. Ranks 1..N−1 load the dataset
// from rank 0's path and serve jobs (ServeViews) until rank 0 stops them. One evaluation:
//   1. rank 0 broadcasts a header, the parts of the RenderState that changed since the last
//      evaluation (scene, positions, material, settings) and the job list with each job's rank;
//      adjoint weights go to the job's rank alone;
//   2. every rank renders its jobs in job order (the jobs are cut into contiguous runs, rank 0's
//      first, balanced by each (view, pass)'s last measured render time and each rank's last
//      measured speed);
//   3. rank 0 consumes its own results, then receives the others' in job order, so the render
//      cache stores and sums (adjoint gradients) in the order a single process does: results are
//      identical to the bit for any rank count.
// Built without MPI (CMake option SFT_MPI off), Launched() is false and nothing here is used.
// A process not started by mpirun never initializes MPI.
#ifndef SFT_OPTIM_MPI_VIEWS_H_
#define SFT_OPTIM_MPI_VIEWS_H_

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

 private:
  MpiSession() = default;
  int rank_ = 0;
  int size_ = 1;
};

// The ranks' agreement before a run; every rank calls it once. Rank 0 passes `own` (its status
// so far: an error stops every rank), the dataset path its workers load and the smallest number of
// views any stage fits (more ranks than that is an error). Workers read the dataset from that
// path into *dataset and report. Every rank returns the same verdict: OK, or one error line
// naming the rank and its reason ("rank 1: ...").
Status MpiHandshake(const MpiSession& session, const Status& own, const std::string& dataset_path,
                    int fitted_views, Dataset* dataset);

// Rank 0's ViewRunner. Stop() (or the destructor) releases the workers.
class MpiViewRunner : public ViewRunner {
 public:
  // `timeout_seconds` bounds every wait for a worker's result (> 0); when it passes, the run
  // ends (MPI_Abort on every rank) with one error line naming the rank.
  MpiViewRunner(const MpiSession& session, double timeout_seconds);
  ~MpiViewRunner() override;
  void Run(const RenderState& state, const std::vector<ViewJob>& jobs, const LocalRender& local,
           const Consume& consume) override;
  void Stop();
  const MpiViewStats& stats() const { return stats_; }

 private:
  // The rank of every job: contiguous runs, rank 0's first, balanced by the measured costs
  // (*cost: each job's) and the ranks' measured speeds.
  std::vector<int> Assign(const RenderState& state, const std::vector<ViewJob>& jobs,
                          std::vector<double>* cost) const;
  void BroadcastState(const RenderState& state, int64_t header[]);

  int size_ = 1;
  double timeout_ = 3600.0;
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
Status ServeViews(const MpiSession& session, const Dataset& dataset);

}  // namespace sft

#endif  // SFT_OPTIM_MPI_VIEWS_H_
