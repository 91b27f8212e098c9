#include "src/io/npz.h"

#include <zip.h>

#include <memory>

#include "src/core/file_util.h"

namespace sft {
namespace {

struct ZipCloser {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};
struct ZipFileCloser {
  void operator()(zip_file_t* file) const { zip_fclose(file); }
};

std::string ErrorText(zip_error_t* error) {
  const std::string text = zip_error_strerror(error);
  zip_error_fini(error);
  return text;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Reads member `index` (of `size` uncompressed bytes) whole.
Status ReadMember(zip_t* archive, zip_uint64_t index, const std::string& where, uint64_t size,
                  std::string* contents) {
  std::unique_ptr<zip_file_t, ZipFileCloser> file(zip_fopen_index(archive, index, 0));
  if (!file) {
    return Status::Error(where + ": cannot open (" + zip_strerror(archive) + ")");
  }
  contents->assign(size, '\0');
  uint64_t done = 0;
  while (done < size) {
    const zip_int64_t n = zip_fread(file.get(), &(*contents)[done], size - done);
    if (n < 0) {
      return Status::Error(where + ": cannot read (" +
                           std::string(zip_error_strerror(zip_file_get_error(file.get()))) + ")");
    }
    if (n == 0) break;
    done += static_cast<uint64_t>(n);
  }
  char extra;
  if (done != size || zip_fread(file.get(), &extra, 1) != 0) {
    return Status::Error(where + ": the member's size differs from the zip directory's");
  }
  return Status::Ok();
}

}  // namespace

Status ParseNpz(const std::string& bytes, const std::string& file,
                std::map<std::string, NpyArray>* arrays) {
  arrays->clear();
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
  if (source == nullptr) return Status::Error(file + ": " + ErrorText(&error));
  std::unique_ptr<zip_t, ZipCloser> archive(zip_open_from_source(source, ZIP_RDONLY, &error));
  if (!archive) {
    zip_source_free(source);
    return Status::Error(file + ": not a readable zip archive (" + ErrorText(&error) + ")");
  }
  zip_error_fini(&error);
  const zip_int64_t members = zip_get_num_entries(archive.get(), 0);
  if (members < 0 || members > kMaxNpzMembers) {
    return Status::Error(file + ": " + std::to_string(members) + " members (at most " +
                         std::to_string(kMaxNpzMembers) + ")");
  }
  int64_t total = 0;
  for (zip_int64_t i = 0; i < members; ++i) {
    zip_stat_t stat;
    zip_stat_init(&stat);
    if (zip_stat_index(archive.get(), i, 0, &stat) != 0 || (stat.valid & ZIP_STAT_NAME) == 0 ||
        (stat.valid & ZIP_STAT_SIZE) == 0) {
      return Status::Error(file + ": member " + std::to_string(i) + ": unreadable directory entry");
    }
    const std::string name = stat.name;
    if (!EndsWith(name, ".npy")) continue;
    const std::string where = file + ": " + name;
    if (stat.size > static_cast<uint64_t>(kMaxNpzMemberBytes) ||
        total + static_cast<int64_t>(stat.size) > kMaxNpzTotalBytes) {
      return Status::Error(where + ": " + std::to_string(stat.size) +
                           " bytes uncompressed is more than sft accepts");
    }
    total += static_cast<int64_t>(stat.size);
    std::string contents;
    SFT_RETURN_IF_ERROR(ReadMember(archive.get(), i, where, stat.size, &contents));
    const std::string key = name.substr(0, name.size() - 4);
    if (arrays->count(key) > 0) return Status::Error(where + ": duplicate member");
    SFT_RETURN_IF_ERROR(ParseNpy(contents, where, &(*arrays)[key]));
  }
  return Status::Ok();
}

Status ReadNpz(const std::string& path, std::map<std::string, NpyArray>* arrays) {
  if (!FileExists(path)) return Status::Error(path + ": file not found");
  std::string bytes;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &bytes));
  return ParseNpz(bytes, path, arrays);
}

}  // namespace sft
