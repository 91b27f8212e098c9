// Bad input to `sft import nerf`, `idr` and `middlebury`: one error line naming the file and
// field, exit code 1, nothing written outside --out (inputs unchanged), no output folder left.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <map>

#include "src/core/file_util.h"
#include "src/io/dataset.h"
#include "tests/testing/calibrated_fixtures.h"
#include "tests/testing/npz_writer.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::map<std::string, std::string> Snapshot(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string rel = fs::relative(entry.path(), root).string();
    if (rel.rfind("out", 0) == 0) continue;
    files[rel] = entry.is_regular_file() ? testing::ReadTestFile(entry.path().string()) : "";
  }
  return files;
}

void Replace(std::string* s, const std::string& key, const std::string& value) {
  for (size_t at = s->find(key); at != std::string::npos; at = s->find(key, at + value.size())) {
    s->replace(at, key.size(), value);
  }
}

struct Case {
  std::string name;
  std::string args;  // {dir} is the fixture folder; --out {dir}/out is added.
  std::function<void(const fs::path& dir)> prepare;
  std::string error_mentions;
};

// A 4-view synth dataset in DIR/ds with its views as transforms.json, par.txt and an IDR folder.
void MakeFixture(const fs::path& dir) {
  ASSERT_EQ(
      testing::SynthIcosphere((dir / "ds").string(), "--cameras 4 --zooms 1 --res 32 --spp 1"), "");
  Dataset dataset;
  ASSERT_TRUE(ReadDataset((dir / "ds").string(), &dataset).ok());
  testing::WriteNerfTransforms(dataset);
  testing::WriteMiddleburyPar(dataset, -1);
  testing::WriteIdrFolder(dataset, 0.6);
}

std::string Npy44(double scale) {
  std::vector<double> v(16, 0.0);
  v[0] = v[5] = v[10] = scale;
  v[15] = 1;
  return testing::NpyBytes({4, 4}, v);
}

TEST(ImportCalibratedHostileTest, FailWithOneLineAndWriteNothing) {
  const std::string nerf = "nerf --transforms {dir}/ds/images/transforms.json";
  const std::string mb = "middlebury --par {dir}/ds/images/par.txt";
  const std::string idr = "idr --cameras {dir}/ds/idr/cameras.npz";
  auto write = [](const std::string& rel, const std::string& text) {
    return [rel, text](const fs::path& d) { testing::WriteTestFile((d / rel).string(), text); };
  };
  const std::vector<Case> cases = {
      {"nerf: missing file", "nerf --transforms {dir}/nope.json", nullptr,
       "--transforms: {dir}/nope.json: file not found"},
      {"nerf: malformed JSON", nerf, write("ds/images/transforms.json", "{\"frames\": [1,"),
       "transforms.json: parse error"},
      {"nerf: 3x4 matrix", nerf,
       write("ds/images/transforms.json",
             R"({"fl_x": 30, "frames": [{"file_path": "000",
                 "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4]]}]})"),
       "transforms.json: frames[0].transform_matrix: expected 4 rows of 4 finite numbers"},
      {"nerf: missing image", nerf, [](const fs::path& d) { fs::remove(d / "ds/images/002.exr"); },
       "frames[2].file_path: {dir}/ds/images/002: no image file"},
      {"nerf: masks auto", nerf + " --masks auto", nullptr,
       "--masks auto: GrabCut needs the sparse points"},
      {"nerf: missing mask", nerf + " --masks {dir}/ds/masks",
       [](const fs::path& d) { fs::remove(d / "ds/masks/001.png"); },
       "mask of image 001.exr not found"},
      {"middlebury: missing file", "middlebury --par {dir}/ds/nope.txt", nullptr,
       "--par: {dir}/ds/nope.txt: file not found"},
      {"middlebury: bad number", mb,
       write("ds/images/par.txt",
             "1\n000.exr 1 0 1 0 1 1 0 0 x "
             "1 0 0 0 1 0 0 0 1 0 0 3\n"),
       "par.txt: line 2: k33: expected a finite number"},
      {"middlebury: short line", mb, write("ds/images/par.txt", "1\n000.exr 1 0 1\n"),
       "par.txt: line 2: expected 22 fields"},
      {"middlebury: no image at all", mb,
       write("ds/images/par.txt", "1\nnone.png 9 0 1 0 9 1 0 0 1 1 0 0 0 1 0 0 0 1 0 0 3\n"),
       "par.txt: none of the 1 images exists"},
      {"middlebury: bad threshold", mb + " --masks threshold --threshold 1.5", nullptr,
       "--threshold: must be in [0, 1)"},
      {"idr: missing file", "idr --cameras {dir}/nope.npz --images {dir}/ds/idr/image", nullptr,
       "--cameras: {dir}/nope.npz: file not found"},
      {"idr: not a zip", idr, write("ds/idr/cameras.npz", "world_mat_0 = [[1, 0]]"),
       "cameras.npz: not a readable zip archive"},
      {"idr: wrong shape", idr,
       [](const fs::path& d) {
         testing::WriteZip(
             (d / "ds/idr/cameras.npz").string(),
             {{"world_mat_0.npy", testing::NpyBytes({3, 3}, std::vector<double>(9))}});
       },
       "cameras.npz: world_mat_0: shape (3, 3), expected (4, 4) or (3, 4)"},
      {"idr: big-endian", idr,
       [](const fs::path& d) {
         testing::WriteZip(
             (d / "ds/idr/cameras.npz").string(),
             {{"world_mat_0.npy", testing::NpyBytes({4, 4}, std::vector<double>(16), ">f8")}});
       },
       "cameras.npz: world_mat_0.npy: descr '>f8' is not supported"},
      {"idr: more images than cameras", idr,
       [](const fs::path& d) {
         testing::WriteZip((d / "ds/idr/cameras.npz").string(), {{"world_mat_0.npy", Npy44(30)}});
       },
       "image: 4 images, but {dir}/ds/idr/cameras.npz has 1 cameras"},
      {"idr: missing image folder", idr + " --images {dir}/nowhere", nullptr,
       "--images: {dir}/nowhere: folder not found"},
      {"idr: mask count", idr + " --masks {dir}/ds/idr/mask",
       [](const fs::path& d) { fs::remove(d / "ds/idr/mask/m003.png"); },
       "3 masks, but there are 4 images"},
  };
  testing::TempDir fixture;
  MakeFixture(fixture.path());
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    testing::TempDir tmp;
    const fs::path dir(tmp.path());
    fs::copy(fixture.Join("ds"), dir / "ds", fs::copy_options::recursive);
    if (c.prepare) c.prepare(dir);
    const auto before = Snapshot(dir);
    std::string args = "import " + c.args + " --out {dir}/out";
    std::string mentions = c.error_mentions;
    Replace(&args, "{dir}", dir.string());
    Replace(&mentions, "{dir}", dir.string());
    std::string output;
    EXPECT_EQ(testing::RunSft(args, &output), 1) << output;
    const size_t at = output.rfind("sft import ");
    ASSERT_NE(at, std::string::npos) << output;
    const std::string last = output.substr(at);
    EXPECT_THAT(last, HasSubstr(": error: ")) << output;
    EXPECT_EQ(testing::CountLines(last), 1) << output;
    EXPECT_THAT(last, HasSubstr(mentions));
    EXPECT_TRUE(before == Snapshot(dir)) << "files outside out/ changed";
    EXPECT_FALSE(fs::exists(dir / "out")) << "out/ written on failure";
    EXPECT_FALSE(fs::exists(dir / "out.partial")) << "temporary folder left behind";
  }
}

}  // namespace
}  // namespace sft
