#include "src/optim/mpi_views.h"

#include <glog/logging.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <thread>
#include <type_traits>

#ifdef SFT_HAVE_MPI
#include <mpi.h>
#include <signal.h>
#include <unistd.h>
#endif

#include "src/io/lights_file.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/mpi_wire.h"
#include "src/optim/state_renderer.h"

namespace sft {

nlohmann::json MpiViewStatsJson(const MpiViewStats& s) {
  return {{"ranks", s.ranks},
          {"evaluations", s.evaluations},
          {"remote_jobs", s.remote_jobs},
          {"seconds",
           {{"broadcast", s.broadcast},
            {"local_render", s.local_render},
            {"imbalance", s.imbalance},
            {"worker_idle", s.worker_idle},
            {"gather", s.gather}}},
          {"broadcast_bytes", s.broadcast_bytes},
          {"gather_bytes", s.gather_bytes}};
}

bool MpiSession::Launched() {
#ifdef SFT_HAVE_MPI
  // Open MPI's launcher (OMPI_COMM_WORLD_SIZE), PMIx launchers (PMIX_RANK) and MPICH's Hydra
  // (PMI_SIZE) set these in every process they start.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"}) {
    if (std::getenv(name) != nullptr) return true;
  }
#endif
  return false;
}

#ifndef SFT_HAVE_MPI

Status MpiSession::Start(std::unique_ptr<MpiSession>*) {
  return Status::Error("sft was built without MPI (CMake option SFT_MPI)");
}
MpiSession::~MpiSession() = default;
int MpiSession::DeadRank() const { return -1; }
void MpiSession::Abort(int code) const { std::_Exit(code); }
Status MpiHandshake(const MpiSession&, const Status& own, const std::string&, int, Dataset*,
                    const std::vector<LightSpec>&) {
  return own;
}
MpiViewRunner::MpiViewRunner(const MpiSession& session, double, const std::atomic<bool>*)
    : session_(session) {}
MpiViewRunner::~MpiViewRunner() = default;
bool MpiViewRunner::failed() { return false; }
void MpiViewRunner::Run(const RenderState&, const std::vector<ViewJob>&, const LocalRender&,
                        const Consume&) {
  LOG(FATAL) << "MpiViewRunner without MPI";
}
void MpiViewRunner::Stop() {}
Status ServeViews(const MpiSession&, const Dataset&) {
  return Status::Error("sft was built without MPI (CMake option SFT_MPI)");
}

#else  // SFT_HAVE_MPI

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Message tags: the job index k's adjoint weights travel with tag 2k + 1, its result with 2k + 2.
int WeightsTag(size_t k) { return static_cast<int>(2 * k + 1); }
int ResultTag(size_t k) { return static_cast<int>(2 * k + 2); }

enum Command : int64_t { kStop = 0, kRun = 1 };
// The broadcast header: command, job count, state parts' mask, state bytes, job-list bytes.
constexpr int kHeaderSize = 5;
// Messages larger than MPI's int count go in pieces of at most kPiece bytes, after their size.
constexpr int64_t kPiece = int64_t{1} << 30;

// Starts sending `bytes` (which must live until the requests complete) to `dest`.
void SendBytes(const std::vector<char>& bytes, int dest, int tag, int64_t* size,
               std::vector<MPI_Request>* requests) {
  *size = static_cast<int64_t>(bytes.size());
  requests->emplace_back();
  MPI_Isend(size, 1, MPI_INT64_T, dest, tag, MPI_COMM_WORLD, &requests->back());
  for (int64_t at = 0; at < *size; at += kPiece) {
    const int n = static_cast<int>(std::min(kPiece, *size - at));
    requests->emplace_back();
    MPI_Isend(bytes.data() + at, n, MPI_BYTE, dest, tag, MPI_COMM_WORLD, &requests->back());
  }
}

// Health check of a wait, called with the seconds waited so far: false ends the wait.
using Watch = std::function<bool(double waited)>;

// Polls `requests` every `period` until they complete (true) or `watch` says stop (false). MPI
// has no timed wait, and Open MPI's waits poll at full speed: a worker that waits that way (for
// rank 0's next evaluation, or for rank 0 to take its results) takes a core from rank 0's
// renders and Ceres on a shared machine.
bool WaitWhile(std::vector<MPI_Request>* requests, std::chrono::microseconds period,
               const Watch& watch) {
  const auto start = Clock::now();
  int done = 0;
  MPI_Testall(static_cast<int>(requests->size()), requests->data(), &done, MPI_STATUSES_IGNORE);
  while (!done) {
    if (watch && !watch(Since(start))) return false;
    std::this_thread::sleep_for(period);
    MPI_Testall(static_cast<int>(requests->size()), requests->data(), &done, MPI_STATUSES_IGNORE);
  }
  return true;
}

// A worker's waits: every 200 µs, unbounded (rank 0 ends the run when it cannot go on).
void WaitIdle(std::vector<MPI_Request>* requests) {
  WaitWhile(requests, std::chrono::microseconds(200), nullptr);
}

// Rank 0's waits: every 100 µs, while `watch` holds.
bool WaitWatched(std::vector<MPI_Request>* requests, const Watch& watch) {
  return WaitWhile(requests, std::chrono::microseconds(100), watch);
}

// The evaluation header, broadcast non-blocking on every rank (a blocking and a non-blocking
// broadcast do not match), so that idle workers wait for it without spinning.
bool BroadcastHeader(int64_t header[], const Watch& watch = nullptr) {
  std::vector<MPI_Request> request(1);
  MPI_Ibcast(header, kHeaderSize, MPI_INT64_T, 0, MPI_COMM_WORLD, &request[0]);
  if (!watch) {
    WaitIdle(&request);
    return true;
  }
  return WaitWatched(&request, watch);
}

// The broadcasts of an evaluation (state, job list): non-blocking as the header, so that rank 0
// (with a watch) notices a rank that stopped taking them. Workers pass no watch.
bool BroadcastPieces(std::vector<char>* bytes, int64_t size, const Watch& watch) {
  bytes->resize(static_cast<size_t>(size));
  for (int64_t at = 0; at < size; at += kPiece) {
    const int n = static_cast<int>(std::min(kPiece, size - at));
    std::vector<MPI_Request> request(1);
    MPI_Ibcast(bytes->data() + at, n, MPI_BYTE, 0, MPI_COMM_WORLD, &request[0]);
    if (!watch) {
      WaitIdle(&request);
    } else if (!WaitWatched(&request, watch)) {
      return false;
    }
  }
  return true;
}

// Rank 0 receives a message sent by SendBytes (false when `watch` stopped the wait).
bool ReceiveBytes(int source, int tag, const Watch& watch, std::vector<char>* bytes) {
  int64_t size = 0;
  std::vector<MPI_Request> request(1);
  MPI_Irecv(&size, 1, MPI_INT64_T, source, tag, MPI_COMM_WORLD, &request[0]);
  if (!WaitWatched(&request, watch)) return false;
  bytes->resize(static_cast<size_t>(size));
  for (int64_t at = 0; at < size; at += kPiece) {
    const int n = static_cast<int>(std::min(kPiece, size - at));
    MPI_Irecv(bytes->data() + at, n, MPI_BYTE, source, tag, MPI_COMM_WORLD, &request[0]);
    if (!WaitWatched(&request, watch)) return false;
  }
  return true;
}

// The handshake's broadcasts (blocking: every rank is there before the run).
void BroadcastBytes(std::vector<char>* bytes, int64_t size) {
  bytes->resize(static_cast<size_t>(size));
  for (int64_t at = 0; at < size; at += kPiece) {
    const int n = static_cast<int>(std::min(kPiece, size - at));
    MPI_Bcast(bytes->data() + at, n, MPI_BYTE, 0, MPI_COMM_WORLD);
  }
}

void BroadcastString(std::string* s) {
  int64_t size = static_cast<int64_t>(s->size());
  MPI_Bcast(&size, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
  std::vector<char> bytes(s->begin(), s->end());
  BroadcastBytes(&bytes, size);
  s->assign(bytes.begin(), bytes.end());
}

// The job list as broadcast: view, pass, seed and rank of each job, and the size of its adjoint
// weights (sent to that rank alone, into a buffer it posts as soon as it has the list).
struct JobEntry {
  int32_t view;
  int32_t pass;
  uint64_t seed;
  int32_t rank;
  int32_t width, height, channels;
};

// What makes process ids comparable: the boot (the machine) and the PID namespace (the
// container); "" when unknown (not Linux), and then no rank is checked.
std::string MachineId() {
  std::ifstream boot("/proc/sys/kernel/random/boot_id");
  std::string id;
  if (!(boot >> id)) return "";
  char ns[128] = {};
  if (readlink("/proc/self/ns/pid", ns, sizeof(ns) - 1) <= 0) return "";
  return id + " " + ns;
}

struct ProcessEntry {
  char machine[128];
  int64_t pid;
};

// Whether process `pid` of this machine still runs: it exists and is not a zombie (a killed
// rank stays one until its launcher reaps it).
bool ProcessRuns(pid_t pid) {
  if (kill(pid, 0) != 0 && errno == ESRCH) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;  // no /proc: kill's answer stands.
  const size_t paren = line.rfind(')');
  const char state = paren + 2 < line.size() ? line[paren + 2] : '?';
  return state != 'Z' && state != 'X';
}

}  // namespace

Status MpiSession::Start(std::unique_ptr<MpiSession>* session) {
  int provided = 0;
  if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    return Status::Error("MPI_Init_thread failed");
  }
  std::unique_ptr<MpiSession> s(new MpiSession());
  MPI_Comm_rank(MPI_COMM_WORLD, &s->rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &s->size_);
  // Rank 0 learns which ranks share its machine, and their process ids (DeadRank).
  const std::string machine = MachineId();
  ProcessEntry own = {};
  std::strncpy(own.machine, machine.c_str(), sizeof(own.machine) - 1);
  own.pid = static_cast<int64_t>(getpid());
  std::vector<ProcessEntry> all(s->rank_ == 0 ? s->size_ : 0);
  MPI_Gather(&own, sizeof(own), MPI_BYTE, all.data(), sizeof(own), MPI_BYTE, 0, MPI_COMM_WORLD);
  for (const ProcessEntry& e : all) {
    const bool here = !machine.empty() && machine == e.machine;
    s->pids_.push_back(here ? e.pid : 0);
  }
  *session = std::move(s);
  return Status::Ok();
}

int MpiSession::DeadRank() const {
  for (size_t r = 1; r < pids_.size(); ++r) {
    if (pids_[r] > 0 && !ProcessRuns(static_cast<pid_t>(pids_[r]))) return static_cast<int>(r);
  }
  return -1;
}

void MpiSession::Abort(int code) const {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);  // MPI_Abort does not return; this says so to the compiler.
}

MpiSession::~MpiSession() { MPI_Finalize(); }

Status MpiHandshake(const MpiSession& session, const Status& own, const std::string& dataset_path,
                    int fitted_views, Dataset* dataset,
                    const std::vector<LightSpec>& estimated_lights) {
  // 1. Rank 0's status, the path and the estimated lights.
  std::string lights;
  Status mine = own;
  if (mine.ok() && !estimated_lights.empty()) {
    mine = LightsFileText(estimated_lights, &lights).Prefixed("estimated lights");
  }
  // Non-blocking: workers wait here without spinning while rank 0 prepares (e.g. carves a hull).
  int64_t go = mine.ok() ? 1 : 0;
  std::vector<MPI_Request> request(1);
  MPI_Ibcast(&go, 1, MPI_INT64_T, 0, MPI_COMM_WORLD, &request[0]);
  WaitIdle(&request);
  if (!go) {
    return session.rank() == 0 ? mine : Status::Error("rank 0 stopped before the run");
  }
  std::string path = dataset_path;
  BroadcastString(&path);
  BroadcastString(&lights);
  // 2. The workers load the dataset, add the estimated lights as rank 0 did (before the fitted
  // map, which the first state brings), and set up the views (environment maps, memory check).
  std::string error;
  if (session.rank() != 0) {
    Status status = ReadDataset(path, dataset);
    std::vector<LightSpec> added;
    if (status.ok() && !lights.empty()) {
      status = ParseLightsFileText(lights, "rank 0's estimated lights", &added);
    }
    if (status.ok()) status = AddEstimatedLights(added, dataset);
    DatasetViews views;
    if (status.ok()) status = MakeDatasetViews(*dataset, &views);
    if (!status.ok()) error = status.message();
  }
  // 3. Rank 0 collects the errors and decides.
  int length = static_cast<int>(error.size());
  std::vector<int> lengths(session.rank() == 0 ? session.size() : 0);
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<int> offsets(lengths.size(), 0);
  int total = 0;
  for (size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = total;
    total += lengths[r];
  }
  std::vector<char> all(static_cast<size_t>(std::max(total, 1)));
  MPI_Gatherv(error.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
              0, MPI_COMM_WORLD);
  std::string verdict;
  if (session.rank() == 0) {
    for (size_t r = 1; r < lengths.size() && verdict.empty(); ++r) {
      if (lengths[r] > 0) {
        verdict = "rank " + std::to_string(r) + ": " +
                  std::string(all.data() + offsets[r], static_cast<size_t>(lengths[r])) +
                  " (every rank reads the dataset from the same path: " + path + ")";
      }
    }
    if (verdict.empty() && session.size() > fitted_views) {
      verdict = "mpirun -np " + std::to_string(session.size()) + ": more ranks than the " +
                std::to_string(fitted_views) + " views fitted (use at most " +
                std::to_string(fitted_views) + " ranks)";
    }
  }
  BroadcastString(&verdict);
  return verdict.empty() ? Status::Ok() : Status::Error(verdict);
}

MpiViewRunner::MpiViewRunner(const MpiSession& session, double timeout_seconds,
                             const std::atomic<bool>* terminating)
    : session_(session),
      size_(session.size()),
      timeout_(timeout_seconds),
      terminating_(terminating),
      speed_(session.size(), 1.0) {
  stats_.ranks = size_;
}

MpiViewRunner::~MpiViewRunner() { Stop(); }

void MpiViewRunner::Stop() {
  if (stopped_) return;
  stopped_ = true;
  if (failed()) {
    LOG(ERROR) << failure_ << ": ending every rank";
    session_.Abort(1);
  }
  int64_t header[kHeaderSize] = {kStop, 0, 0, 0, 0};
  BroadcastHeader(header, [this](double waited) { return Healthy(-1, waited); });
}

bool MpiViewRunner::failed() { return !Healthy(-1, 0.0); }

bool MpiViewRunner::Healthy(int rank, double waited) {
  if (!failure_.empty()) return false;
  const int dead = session_.DeadRank();
  if (dead > 0) {
    failure_ = "rank " + std::to_string(dead) + " stopped answering (died or was killed)";
  } else if (waited > timeout_) {
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%g", timeout_);
    failure_ = (rank > 0 ? "rank " + std::to_string(rank) : std::string("a rank")) +
               " stopped answering (nothing for " + seconds + " s, --mpi-timeout)";
  } else if (terminating_ != nullptr && terminating_->load()) {
    failure_ = "the MPI launcher is ending the run (SIGTERM: another rank died or was killed?)";
  }
  return failure_.empty();
}

std::vector<int> MpiViewRunner::Assign(const RenderState& state, const std::vector<ViewJob>& jobs,
                                       std::vector<double>* cost) const {
  cost->assign(jobs.size(), 1.0);
  double total = 0.0;
  for (size_t k = 0; k < jobs.size(); ++k) {
    const auto it = cost_.find({state.view_indices[jobs[k].view], static_cast<int>(jobs[k].pass)});
    if (it != cost_.end()) (*cost)[k] = std::max(it->second, 1e-6);
    total += (*cost)[k];
  }
  // Rank r's share of the total cost is proportional to its measured speed; job k goes to the
  // rank whose share holds the middle of its cost.
  std::vector<double> end(size_);
  double speeds = 0.0;
  for (int r = 0; r < size_; ++r) speeds += speed_[r];
  double sum = 0.0;
  for (int r = 0; r < size_; ++r) {
    sum += speed_[r];
    end[r] = total * sum / speeds;
  }
  std::vector<int> rank(jobs.size());
  double before = 0.0;
  int r = 0;
  for (size_t k = 0; k < jobs.size(); ++k) {
    const double middle = before + 0.5 * (*cost)[k];
    while (r < size_ - 1 && middle > end[r]) ++r;
    rank[k] = r;
    before += (*cost)[k];
  }
  return rank;
}

bool MpiViewRunner::BroadcastState(const RenderState& state, int64_t header[]) {
  std::vector<std::vector<char> > parts = StateParts(state);
  if (sent_parts_.size() != parts.size()) sent_parts_.assign(parts.size(), {});
  // A new scene resends the positions too: the workers rebuild from the build positions.
  if (parts[kScenePart] != sent_parts_[kScenePart]) sent_parts_[kPositionsPart].clear();
  std::vector<char> changed;
  int64_t mask = 0;
  for (size_t p = 0; p < parts.size(); ++p) {
    if (parts[p] == sent_parts_[p]) continue;
    mask |= int64_t{1} << p;
    ByteWriter w;
    w.PutVector(parts[p]);
    changed.insert(changed.end(), w.bytes().begin(), w.bytes().end());
    sent_parts_[p] = std::move(parts[p]);
  }
  header[2] = mask;
  header[3] = static_cast<int64_t>(changed.size());
  const Watch watch = [this](double waited) { return Healthy(-1, waited); };
  if (!BroadcastHeader(header, watch)) return false;
  if (!changed.empty() && !BroadcastPieces(&changed, header[3], watch)) return false;
  stats_.broadcast_bytes += header[3];
  return true;
}

void MpiViewRunner::Run(const RenderState& state, const std::vector<ViewJob>& jobs,
                        const LocalRender& local, const Consume& consume) {
  CHECK(!stopped_);
  // After a fault, the jobs from `from` on are rendered here, in job order, as one process
  // would. Requests still pending towards other ranks are left: no MPI call follows a fault but
  // MPI_Abort, so nothing reads their buffers.
  const auto finish_here = [&](size_t from) {
    for (size_t k = from; k < jobs.size(); ++k) {
      const auto render_start = Clock::now();
      ViewResult result;
      local(jobs[k], &result);
      stats_.local_render += Since(render_start);
      consume(k, &result);
    }
  };
  if (failed()) return finish_here(0);
  const auto start = Clock::now();
  std::vector<double> cost;
  const std::vector<int> rank = Assign(state, jobs, &cost);
  // Per rank: the assigned cost and the seconds it took (rank 0: its own renders and storing
  // them; a worker: from its header to its last result), for the next evaluation's speeds.
  std::vector<double> assigned(size_, 0.0), busy(size_, 0.0);
  for (size_t k = 0; k < jobs.size(); ++k) assigned[rank[k]] += cost[k];
  std::vector<JobEntry> entries(jobs.size());
  for (size_t k = 0; k < jobs.size(); ++k) {
    const Image& w = jobs[k].weights;
    entries[k] = {
        jobs[k].view, static_cast<int32_t>(jobs[k].pass), jobs[k].seed, rank[k], w.width, w.height,
        w.channels};
  }
  ByteWriter job_list;
  job_list.PutVector(entries);
  int64_t header[kHeaderSize] = {kRun, static_cast<int64_t>(jobs.size()), 0, 0,
                                 static_cast<int64_t>(job_list.bytes().size())};
  if (!BroadcastState(state, header) ||
      !BroadcastPieces(&job_list.bytes(), header[4],
                       [this](double waited) { return Healthy(-1, waited); })) {
    return finish_here(0);
  }
  stats_.broadcast_bytes += header[4];
  // Adjoint weights to the ranks that render those jobs. Delivered before rank 0 renders: rank 0
  // makes no MPI progress while it renders, and the workers' first jobs need them.
  std::vector<MPI_Request> requests;
  std::vector<int> request_ranks;
  for (size_t k = 0; k < jobs.size(); ++k) {
    if (rank[k] == 0 || jobs[k].pass != ViewPass::kAdjoint) continue;
    request_ranks.push_back(rank[k]);
    const std::vector<float>& data = jobs[k].weights.data;
    CHECK_LT(data.size(), static_cast<size_t>(INT32_MAX));
    requests.emplace_back();
    MPI_Isend(data.data(), static_cast<int>(data.size()), MPI_FLOAT, rank[k], WeightsTag(k),
              MPI_COMM_WORLD, &requests.back());
    stats_.broadcast_bytes += static_cast<int64_t>(data.size() * sizeof(float));
  }
  for (size_t r = 0; r < requests.size(); ++r) {
    std::vector<MPI_Request> request = {requests[r]};
    const int to = request_ranks[r];
    if (!WaitWatched(&request, [&](double waited) { return Healthy(to, waited); })) {
      return finish_here(0);
    }
  }
  const double broadcast_seconds = Since(start);
  stats_.broadcast += broadcast_seconds;
  // Rank 0's own jobs (the first run of jobs), consumed as they finish.
  size_t k = 0;
  for (; k < jobs.size() && rank[k] == 0; ++k) {
    const auto render_start = Clock::now();
    ViewResult result;
    local(jobs[k], &result);
    stats_.local_render += Since(render_start);
    cost_[{state.view_indices[jobs[k].view], static_cast<int>(jobs[k].pass)}] = result.seconds;
    consume(k, &result);
  }
  const double local_done = Since(start);
  busy[0] = local_done - broadcast_seconds;
  // The others', in job order. Rank 0 waits whenever it is not storing a result; of that wait,
  // the time the slowest rank was still rendering after rank 0 had finished is imbalance (the
  // workers' clocks start at the header, within a broadcast latency of rank 0's), the rest gather.
  double storing = 0.0, last_ready = 0.0;
  for (; k < jobs.size(); ++k) {
    std::vector<char> bytes;
    const int from = rank[k];
    if (!ReceiveBytes(
            from, ResultTag(k), [&](double waited) { return Healthy(from, waited); }, &bytes)) {
      return finish_here(k);
    }
    stats_.gather_bytes += static_cast<int64_t>(bytes.size());
    ViewResult result;
    double ready = 0.0;
    GetResult(bytes, &result, &ready);
    last_ready = std::max(last_ready, ready);
    busy[rank[k]] = std::max(busy[rank[k]], ready);
    cost_[{state.view_indices[jobs[k].view], static_cast<int>(jobs[k].pass)}] = result.seconds;
    ++stats_.remote_jobs;
    const auto store_start = Clock::now();
    consume(k, &result);
    storing += Since(store_start);
  }
  const double waited = std::max(0.0, Since(start) - local_done - storing);
  const double imbalance = std::clamp(last_ready - local_done, 0.0, waited);
  double idle = 0.0;
  for (int r = 1; r < size_; ++r) idle += std::max(0.0, local_done - busy[r]);
  stats_.worker_idle += size_ > 1 ? idle / (size_ - 1) : 0.0;
  stats_.imbalance += imbalance;
  stats_.gather += waited - imbalance;
  // A rank that had no jobs gets the fastest speed measured, so that it is tried again; no rank
  // drops below a quarter of the fastest (one slow evaluation must not starve it for good).
  double fastest = 0.0;
  for (int r = 0; r < size_; ++r) {
    if (assigned[r] > 0.0 && busy[r] > 0.0) {
      speed_[r] = assigned[r] / busy[r];
      fastest = std::max(fastest, speed_[r]);
    }
  }
  for (int r = 0; r < size_ && fastest > 0.0; ++r) {
    speed_[r] = assigned[r] > 0.0 ? std::max(speed_[r], 0.25 * fastest) : fastest;
  }
  ++stats_.evaluations;
}

Status ServeViews(const MpiSession& session, const Dataset& dataset) {
  std::unique_ptr<StateRenderer> renderer;
  SFT_RETURN_IF_ERROR(StateRenderer::Create(dataset, &renderer));
  RenderState state;
  // Test hook (ServeViews' comment): results to send before dying; -1 never.
  const char* die_env = std::getenv("SFT_TEST_MPI_DIE_AFTER_JOBS");
  const int64_t die_after = die_env != nullptr ? std::atoll(die_env) : -1;
  int64_t sent = 0;
  for (;;) {
    int64_t header[kHeaderSize];
    BroadcastHeader(header);
    const auto start = Clock::now();
    if (header[0] == kStop) return Status::Ok();
    if (header[3] > 0) {
      std::vector<char> changed;
      BroadcastPieces(&changed, header[3], nullptr);
      ByteReader r(changed);
      for (int p = 0; p < kNumParts; ++p) {
        if (header[2] & (int64_t{1} << p)) ApplyStatePart(p, r.GetVector<char>(), &state);
      }
    }
    std::vector<char> job_bytes;
    BroadcastPieces(&job_bytes, header[4], nullptr);
    ByteReader job_reader(job_bytes);
    const std::vector<JobEntry> entries = job_reader.GetVector<JobEntry>();
    // A worker that cannot render rank 0's state dies: rank 0 sees a dead rank, renders the
    // evaluation itself and ends the run (MpiViewRunner).
    const Status updated = renderer->Update(state);
    if (!updated.ok()) LOG(FATAL) << "rank " << session.rank() << ": " << updated.message();
    // Receives for this rank's adjoint weights, posted at once (rank 0 waits for their delivery).
    std::vector<Image> weights(entries.size());
    std::vector<MPI_Request> weight_requests(entries.size(), MPI_REQUEST_NULL);
    for (size_t k = 0; k < entries.size(); ++k) {
      const JobEntry& e = entries[k];
      if (e.rank != session.rank() || e.pass != static_cast<int32_t>(ViewPass::kAdjoint)) continue;
      weights[k] = Image(e.width, e.height, e.channels);
      MPI_Irecv(weights[k].data.data(), static_cast<int>(weights[k].data.size()), MPI_FLOAT, 0,
                WeightsTag(k), MPI_COMM_WORLD, &weight_requests[k]);
    }
    // Results are sent as they are ready; their buffers live until every send completed.
    std::vector<std::vector<char> > results;
    std::vector<int64_t> sizes(entries.size());
    std::vector<MPI_Request> requests;
    results.reserve(entries.size());
    for (size_t k = 0; k < entries.size(); ++k) {
      if (entries[k].rank != session.rank()) continue;
      if (sent == die_after) {
        WaitIdle(&requests);  // the results sent so far reach rank 0 first.
        std::raise(SIGKILL);
      }
      ++sent;
      ViewJob job;
      job.view = entries[k].view;
      job.pass = static_cast<ViewPass>(entries[k].pass);
      job.seed = entries[k].seed;
      if (job.pass == ViewPass::kAdjoint) {
        std::vector<MPI_Request> request = {weight_requests[k]};
        WaitIdle(&request);
        job.weights = std::move(weights[k]);
      }
      ViewResult result;
      renderer->Render(state, job, &result);
      ByteWriter w;
      PutResult(result, Since(start), &w);
      results.push_back(std::move(w.bytes()));
      SendBytes(results.back(), 0, ResultTag(k), &sizes[k], &requests);
    }
    WaitIdle(&requests);
  }
}

#endif  // SFT_HAVE_MPI

}  // namespace sft
