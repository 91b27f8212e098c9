// A fresh temporary directory per test, removed on destruction.
#ifndef SFT_TESTS_TESTING_TEMP_DIR_H_
#define SFT_TESTS_TESTING_TEMP_DIR_H_

#include <string>

namespace sft {
namespace testing {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::string& path() const { return path_; }
  // path()/relative
  std::string Join(const std::string& relative) const { return path_ + "/" + relative; }

 private:
  std::string path_;
};

// The source tree's data/ directory (fixtures, Cycles reference datasets).
std::string DataDir();
// The project's shared data folder (../shared/data beside the repository: real captures and
// other data that may not be copied into it), or "" when it is absent; tests that need it skip.
std::string SharedDataDir();
// Absolute path of the built `sft` executable (for CLI tests).
std::string SftBinary();
// The whole file at `path` as is (binary); "" when it cannot be read.
std::string ReadTestFile(const std::string& path);
// Writes `contents` to `path` as is (binary), for fixtures written by tests.
void WriteTestFile(const std::string& path, const std::string& contents);
// Runs `sft ARGS` (the built binary), returns its exit code; output as RunCommand.
int RunSft(const std::string& args, std::string* output = nullptr);
// Lines of `text`, counting a last line without its newline.
int CountLines(const std::string& text);
// How often `part` (not empty) occurs in `text`, overlapping occurrences included.
int CountOccurrences(const std::string& text, const std::string& part);
// Runs a shell command, returns its exit code; stdout+stderr captured into *output if non-null.
int RunCommand(const std::string& command, std::string* output = nullptr);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_TEMP_DIR_H_
