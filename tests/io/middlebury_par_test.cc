// Middlebury X_par.txt: parsing, conversion to sft cameras and poses, and one-line errors.
#include "src/io/middlebury_par.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace sft {
namespace {

using ::testing::HasSubstr;

// The first line of the dino set's file (vision.middlebury.edu), as a fact for the test.
constexpr char kDino1[] =
    "dino0001.png 3310.400000 0.000000 316.730000 0.000000 3325.500000 200.550000 0.000000 "
    "0.000000 1.000000 -0.02755613714744022800 0.99855065785218411000 -0.04622970395378579000 "
    "-0.97626728342925628000 -0.03682184943054355600 -0.21341815104932660000 "
    "-0.21481113274439387000 0.03925223953400933800 0.97586583758523360000 "
    "-0.03273720861024858500 -0.00135737867652815920 0.66025659732745012000";

TEST(MiddleburyParTest, ParsesAndConverts) {
  std::vector<MiddleburyEntry> entries;
  const Status status = ParseMiddleburyPar(std::string("2\r\n") + kDino1 + "\r\n\n" + kDino1 + "\n",
                                           "p.txt", &entries);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].image, "dino0001.png");
  EXPECT_EQ(entries[1].line, 4);
  Camera camera;
  ASSERT_TRUE(MiddleburyCamera(entries[0], "p.txt", 640, 480, &camera).ok());
  EXPECT_THAT(camera.params, ::testing::ElementsAre(3310.4, 3325.5, 317.23, 201.05));
  Rigid3d pose;
  ASSERT_TRUE(MiddleburyPose(entries[0], "p.txt", &pose).ok());
  // The camera centre −Rᵀt lies on the set's ring (radius about 0.65 around the object).
  EXPECT_NEAR(pose.Inverse().translation.norm(), 0.66, 0.01);
  EXPECT_LT((pose.rotation.toRotationMatrix() - entries[0].rotation).cwiseAbs().maxCoeff(), 1e-5);
}

std::string ParseError(const std::string& text) {
  std::vector<MiddleburyEntry> entries;
  const Status status = ParseMiddleburyPar(text, "p.txt", &entries);
  EXPECT_FALSE(status.ok());
  return status.message();
}

TEST(MiddleburyParTest, OneLineErrors) {
  const std::string line = kDino1;
  EXPECT_THAT(ParseError(""), HasSubstr("p.txt: empty"));
  EXPECT_THAT(ParseError("two\n" + line), HasSubstr("p.txt: line 1: expected the number"));
  EXPECT_THAT(ParseError("2\n" + line), HasSubstr("announces 2 entries, the file has 1"));
  EXPECT_THAT(ParseError("1\n" + line + "\n" + line), HasSubstr("line 3: more entries"));
  EXPECT_THAT(ParseError("1\n" + line.substr(0, line.rfind(' '))),
              HasSubstr("line 2: expected 22 fields"));
  std::string bad = line;
  bad.replace(bad.find("3310.400000"), 11, "3310.4x");
  EXPECT_THAT(ParseError("1\n" + bad), HasSubstr("line 2: k11: expected a finite number"));
  bad = line;
  bad.replace(0, 12, "../dino.png");
  EXPECT_THAT(ParseError("1\n" + bad), HasSubstr("line 2: image name \"../dino.png\""));
  // A parsed entry with a scaled R is refused when converted.
  std::vector<MiddleburyEntry> entries;
  ASSERT_TRUE(ParseMiddleburyPar("1\n" + line, "p.txt", &entries).ok());
  entries[0].rotation *= 2;
  Rigid3d pose;
  const Status status = MiddleburyPose(entries[0], "p.txt", &pose);
  EXPECT_THAT(status.message(), HasSubstr("p.txt: line 2 (dino0001.png): R: not a rotation"));
}

}  // namespace
}  // namespace sft
