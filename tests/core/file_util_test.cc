#include "src/core/file_util.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(FileUtilTest, ContainedRelativePaths) {
  std::string why;
  EXPECT_TRUE(IsContainedRelativePath("images/000.exr", &why));
  EXPECT_TRUE(IsContainedRelativePath("images/cam1/000.png", &why));
  EXPECT_TRUE(IsContainedRelativePath("./a.png", &why));
  EXPECT_TRUE(IsContainedRelativePath("a..b.png", &why));  // ".." only as a whole component.
  EXPECT_FALSE(IsContainedRelativePath("", &why));
  EXPECT_FALSE(IsContainedRelativePath("/etc/passwd", &why));
  EXPECT_THAT(why, HasSubstr("absolute"));
  EXPECT_FALSE(IsContainedRelativePath("../x.exr", &why));
  EXPECT_THAT(why, HasSubstr(".."));
  EXPECT_FALSE(IsContainedRelativePath("images/../../x.exr", &why));
  EXPECT_FALSE(IsContainedRelativePath("images/..", &why));
  EXPECT_FALSE(IsContainedRelativePath(".", &why));
  EXPECT_FALSE(IsContainedRelativePath("images/", &why));
}

TEST(FileUtilTest, OutputDirectoryNeverOverlapsInputs) {
  testing::TempDir tmp;
  const fs::path root(tmp.path());
  fs::create_directories(root / "ds/images");
  testing::WriteTestFile((root / "ds/scene.json").string(), "{}");
  testing::WriteTestFile((root / "mesh.obj").string(), "v 0 0 0\n");
  fs::create_directory_symlink(root / "ds", root / "link");
  const RunInputs inputs{{(root / "ds").string()}, {(root / "mesh.obj").string(), ""}};
  auto check = [&](const std::string& out) { return CheckOutputDirectory(out, inputs, "--out"); };
  EXPECT_TRUE(check((root / "out").string()).ok());
  EXPECT_TRUE(check((root / "new/deeper/out").string()).ok());
  for (const std::string& bad :
       {(root / "ds").string(), (root / "ds/").string(), (root / "./ds/").string(),
        (root / "link").string(), (root / "link/").string(), (root / "ds/images").string(),
        (root / "ds/new").string(), root.string(), (root / "out/../ds").string(), std::string()}) {
    const Status status = check(bad);
    EXPECT_FALSE(status.ok()) << bad;
    EXPECT_THAT(status.message(), HasSubstr("--out")) << bad;
  }
  testing::WriteTestFile((root / "file").string(), "x");
  EXPECT_FALSE(check((root / "file").string()).ok());
}

TEST(FileUtilTest, OutputFileNeverAnInput) {
  testing::TempDir tmp;
  const fs::path root(tmp.path());
  fs::create_directories(root / "ds");
  testing::WriteTestFile((root / "mesh.obj").string(), "v 0 0 0\n");
  const RunInputs inputs{{(root / "ds").string()}, {(root / "mesh.obj").string()}};
  EXPECT_TRUE(CheckOutputFile((root / "r.json").string(), inputs, "--json").ok());
  EXPECT_FALSE(CheckOutputFile((root / "mesh.obj").string(), inputs, "--json").ok());
  EXPECT_FALSE(CheckOutputFile((root / "./mesh.obj").string(), inputs, "--json").ok());
  EXPECT_FALSE(CheckOutputFile((root / "ds/r.json").string(), inputs, "--json").ok());
  EXPECT_FALSE(CheckOutputFile(root.string(), inputs, "--json").ok());
  EXPECT_FALSE(CheckOutputFile("", inputs, "--json").ok());
}

// A failed rename reports its own reason, not the "Success" of the clean-up that follows it.
TEST(FileUtilTest, FailedWriteNamesTheReason) {
  testing::TempDir tmp;
  const std::string target = tmp.Join("busy");
  fs::create_directories(target + "/child");  // rename() cannot replace a non-empty directory.
  const Status status = WriteTextFile(target, "x");
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("busy: cannot write ("));
  EXPECT_THAT(status.message(), Not(HasSubstr("Success")));
  // No temporary file is left behind.
  int entries = 0;
  for (const auto& entry : fs::directory_iterator(tmp.path())) entries += entry.exists();
  EXPECT_EQ(entries, 1);
}

}  // namespace
}  // namespace sft
