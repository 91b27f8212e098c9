// Status: the error value that crosses the library API for user-input errors (bad files, bad
// options). Programming errors use CHECK/DCHECK instead. A failed Status carries one line of text
// that names the offending file and field, ready for `apps/` to print as is.
#ifndef SFT_CORE_STATUS_H_
#define SFT_CORE_STATUS_H_

#include <string>
#include <utility>

namespace sft {

class Status {
 public:
  Status() = default;  // OK.
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !failed_; }
  const std::string& message() const { return message_; }

  // Returns a copy whose message is "prefix: message" (for adding the file or field context).
  Status Prefixed(const std::string& prefix) const {
    return ok() ? *this : Status(prefix + ": " + message_);
  }

 private:
  explicit Status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  std::string message_;
};

}  // namespace sft

// Returns from the calling function when `expr` yields a failed Status.
#define SFT_RETURN_IF_ERROR(expr)              \
  do {                                         \
    ::sft::Status sft_status_ = (expr);        \
    if (!sft_status_.ok()) return sft_status_; \
  } while (0)

#endif  // SFT_CORE_STATUS_H_
