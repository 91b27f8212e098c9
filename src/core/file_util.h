// Small file helpers: atomic writes (temporary file + rename, so no reader ever sees a half-written
// output) and path joining.
#ifndef SFT_CORE_FILE_UTIL_H_
#define SFT_CORE_FILE_UTIL_H_

#include <functional>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

// Joins `base` and `relative` unless `relative` is absolute.
std::string JoinPath(const std::string& base, const std::string& relative);

// Returns `path`'s lower-case extension without the dot ("exr", "png"; "" if none).
std::string FileExtension(const std::string& path);

// Calls `write(tmp_path)` with a temporary path in the same directory (same extension, so
// extension-sniffing writers work), then renames it to `path`. Creates the parent directory.
// The temporary file is removed when `write` fails.
Status WriteAtomically(const std::string& path,
                       const std::function<Status(const std::string& tmp_path)>& write);

// Writes `contents` to `path` atomically.
Status WriteTextFile(const std::string& path, const std::string& contents);

// strerror(error_number), or "unknown error" for 0 (never "Success" in an error message). Callers
// capture errno right after the failing call, before anything else can change it.
std::string ErrnoText(int error_number);

// Removes a leading UTF-8 byte-order mark (EF BB BF), which some editors write at the start of
// text files (OBJ, OFF, PLY headers, JSON); left in place it would garble the first line.
void StripUtf8Bom(std::string* text);

// Reads a whole file; error names the path.
Status ReadTextFile(const std::string& path, std::string* contents);

// Creates a directory and its parents; OK if it exists.
Status MakeDirectories(const std::string& path);

bool FileExists(const std::string& path);

// Whether `path` may name a file inside a dataset (docs/dataset.md): non-empty, relative, and
// without a ".." component, so that joining it to the dataset folder (or mirroring it under an
// output folder) can never leave that folder. Otherwise false with the reason in *why.
bool IsContainedRelativePath(const std::string& path, std::string* why);

// What a command reads, for CheckOutputLocation: directories (a dataset) and files (a mesh, a
// material JSON, a probe). Empty strings and inline values are ignored by the check.
struct RunInputs {
  std::vector<std::string> directories;
  std::vector<std::string> files;
};

// Refuses an output directory that would put a run's outputs among its inputs: `out` empty, an
// existing non-directory, equal to or inside an input directory, or an ancestor of an input
// directory or file. Paths are compared after resolving symbolic links, "." and ".." (as far as
// they exist), so "./D/" and a symlink to D count as D. `flag` names the option in the error
// ("--out"). Every command that writes calls this before it reads or writes anything.
Status CheckOutputDirectory(const std::string& out, const RunInputs& inputs,
                            const std::string& flag);

// The same for a single output file (--json FILE): refused when empty, a directory, equal to an
// input file, or inside an input directory.
Status CheckOutputFile(const std::string& file, const RunInputs& inputs, const std::string& flag);

}  // namespace sft

#endif  // SFT_CORE_FILE_UTIL_H_
