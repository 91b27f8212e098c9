// The byte format of the messages between MPI ranks (src/optim/mpi_views.h): buffers of plain
// values, the render state's parts and a view's result. A message is only ever read by the same
// executable that wrote it, so values are copied as they are in memory; every rank must therefore
// run the same build. Independent of MPI itself (the transport is in mpi_views.cc).
#ifndef SFT_OPTIM_MPI_WIRE_H_
#define SFT_OPTIM_MPI_WIRE_H_

#include <glog/logging.h>

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "src/optim/view_jobs.h"

namespace sft {

// The state's parts, each sent only when it changed: the scene (id, build positions, faces), the
// vertex positions, the material, the settings (light scales, render options, derivative
// request, parameter layout, image scale, views) and the fitted environment's texels.
enum StatePart {
  kScenePart = 0,
  kPositionsPart,
  kMaterialPart,
  kSettingsPart,
  kEnvironmentPart,
  kNumParts
};

// Values copied as bytes: trivially copyable types and fixed-size Eigen vectors (plain arrays of
// their scalars, though their copy constructors are user-provided).
template <typename T>
struct Plain : std::is_trivially_copyable<T> {};
template <typename S, int R, int C, int O, int MR, int MC>
struct Plain<Eigen::Matrix<S, R, C, O, MR, MC> > : std::is_trivially_copyable<S> {
  static_assert(R != Eigen::Dynamic && C != Eigen::Dynamic, "fixed-size Eigen types only");
};

// Byte buffers of plain values and vectors of them. A message is only ever read by the same
// executable that wrote it, so values are copied as they are in memory.
class ByteWriter {
 public:
  template <typename T>
  void Put(const T& value) {
    static_assert(Plain<T>::value, "plain values only");
    const char* p = reinterpret_cast<const char*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <typename T>
  void PutVector(const std::vector<T>& values) {
    static_assert(Plain<T>::value, "plain values only");
    Put<uint64_t>(values.size());
    const char* p = reinterpret_cast<const char*>(values.data());
    bytes_.insert(bytes_.end(), p, p + values.size() * sizeof(T));
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  std::vector<char> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <typename T>
  T Get() {
    T value;
    CHECK_LE(at_ + sizeof(T), bytes_.size()) << "MPI message shorter than its contents";
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  template <typename T>
  std::vector<T> GetVector() {
    const uint64_t n = Get<uint64_t>();
    CHECK_LE(at_ + n * sizeof(T), bytes_.size()) << "MPI message shorter than its contents";
    std::vector<T> values(n);
    std::memcpy(static_cast<void*>(values.data()), bytes_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return values;
  }

 private:
  const std::vector<char>& bytes_;
  size_t at_ = 0;
};

// The serialized parts of a state (StatePart order).
std::vector<std::vector<char> > StateParts(const RenderState& s);

// Applies one serialized part (`part`: a StatePart) to a worker's state.
void ApplyStatePart(int part, const std::vector<char>& bytes, RenderState* s);

// A result on the wire: the ViewResult and the worker's seconds from the run's header to the
// result being ready (the balance's measure of when that rank finished).
void PutResult(const ViewResult& result, double ready_seconds, ByteWriter* w);
void GetResult(const std::vector<char>& bytes, ViewResult* result, double* ready_seconds);

}  // namespace sft

#endif  // SFT_OPTIM_MPI_WIRE_H_
