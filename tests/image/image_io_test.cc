#include "src/image/image_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::DataDir;
using ::testing::HasSubstr;
using ::testing::SizeIs;
using testing::TempDir;

// Exact sRGB decode in double precision, to check against.
double SrgbDecode(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

std::vector<std::string> ListDir(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  return names;
}

TEST(ImageIoSrgb, KnownValues) {
  EXPECT_NEAR(SrgbToLinear(0.5f), 0.214041f, 1e-6);
  EXPECT_NEAR(LinearToSrgb(0.214041f), 0.5f, 1e-6);
  EXPECT_EQ(SrgbToLinear(0.0f), 0.0f);
  EXPECT_EQ(SrgbToLinear(1.0f), 1.0f);
  EXPECT_EQ(LinearToSrgb(1.0f), 1.0f);
  // The linear segment and its joint with the power segment.
  EXPECT_NEAR(SrgbToLinear(0.02f), 0.02f / 12.92f, 1e-9);
  EXPECT_NEAR(SrgbToLinear(0.04045f), 0.0031308f, 1e-6);
  EXPECT_NEAR(LinearToSrgb(0.0031308f), 0.04045f, 1e-5);
  // Out of range input is clamped, NaN maps to 0.
  EXPECT_EQ(SrgbToLinear(-0.5f), 0.0f);
  EXPECT_EQ(LinearToSrgb(2.0f), 1.0f);
  EXPECT_EQ(LinearToSrgb(std::numeric_limits<float>::quiet_NaN()), 0.0f);
}

TEST(ImageIoSrgb, RoundTripIsIdentity) {
  for (int i = 0; i <= 100; ++i) {
    const float v = i / 100.0f;
    EXPECT_NEAR(LinearToSrgb(SrgbToLinear(v)), v, 2e-6) << v;
    EXPECT_NEAR(SrgbToLinear(v), SrgbDecode(v), 1e-6) << v;
  }
}

class ImageIoExrTest : public ::testing::TestWithParam<int> {};

TEST_P(ImageIoExrTest, RoundTripIsExact) {
  const int channels = GetParam();
  TempDir dir;
  // 17x9 is compressed by the writer, 3x2 is not: cover both.
  for (const auto& [w, h] : {std::pair<int, int>{17, 9}, std::pair<int, int>{3, 2}}) {
    Image image(w, h, channels);
    for (size_t i = 0; i < image.data.size(); ++i) {
      image.data[i] = (static_cast<float>(i) - 7.0f) * 0.123456789f + 1e-7f * i;
    }
    image.at(0, 0, 0) = 1e6f;
    const std::string path = dir.Join("sub/rt" + std::to_string(w) + ".exr");
    const Status written = WriteExr(path, image);
    ASSERT_TRUE(written.ok()) << written.message();
    Image read;
    const Status status = ReadImage(path, &read);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(read.width, w);
    EXPECT_EQ(read.height, h);
    EXPECT_EQ(read.channels, channels);
    EXPECT_EQ(read.data, image.data);  // float32 storage: bit-exact.
  }
  // Atomic writes leave no temporary files behind.
  EXPECT_THAT(ListDir(dir.Join("sub")), SizeIs(2));
}

INSTANTIATE_TEST_SUITE_P(Channels, ImageIoExrTest, ::testing::Values(1, 3, 4));

TEST(ImageIoExr, ChannelOrderIsRgb) {
  TempDir dir;
  Image image(2, 1, 4);
  image.data = {0.1f, 0.2f, 0.3f, 0.4f, 1.0f, 2.0f, 3.0f, 4.0f};
  ASSERT_TRUE(WriteImage(dir.Join("a.EXR"), image).ok());
  Image read;
  ASSERT_TRUE(ReadImage(dir.Join("a.EXR"), &read).ok());
  EXPECT_FLOAT_EQ(read.at(0, 0, 0), 0.1f);
  EXPECT_FLOAT_EQ(read.at(0, 0, 2), 0.3f);
  EXPECT_FLOAT_EQ(read.at(1, 0, 3), 4.0f);
}

TEST(ImageIoExr, ReadsCyclesRender) {
  Image image;
  const Status status = ReadImage(DataDir() + "/cycles/bunny_point_diffuse/images/000.exr", &image);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(image.width, 128);
  EXPECT_EQ(image.height, 128);
  EXPECT_EQ(image.channels, 4);  // RGBA, alpha = coverage (data/cycles/README.md).
  float max_alpha = 0, min_alpha = 1;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      max_alpha = std::max(max_alpha, image.at(x, y, 3));
      min_alpha = std::min(min_alpha, image.at(x, y, 3));
    }
  }
  EXPECT_NEAR(max_alpha, 1.0f, 1e-3);
  EXPECT_NEAR(min_alpha, 0.0f, 1e-3);
}

TEST(ImageIoExr, CorruptFileNamesPath) {
  TempDir dir;
  const std::string path = dir.Join("bad.exr");
  testing::WriteTestFile(path, "this is not an OpenEXR file at all");
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path));
}

TEST(ImageIoExr, TruncatedFileNamesPath) {
  TempDir dir;
  Image image(64, 64, 3, 0.5f);
  const std::string good = dir.Join("good.exr");
  ASSERT_TRUE(WriteExr(good, image).ok());
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string bad = dir.Join("truncated.exr");
  testing::WriteTestFile(bad, bytes.substr(0, bytes.size() / 2));
  Image read;
  const Status status = ReadImage(bad, &read);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(bad));
}

// Writes an image with OpenCV directly (BGR order) so that the reader is tested independently
// of WritePng.
TEST(ImageIoPng, Reads8BitWithSrgbDecodeAndRgbOrder) {
  TempDir dir;
  cv::Mat mat(1, 3, CV_8UC3);
  mat.at<cv::Vec3b>(0, 0) = cv::Vec3b(0, 128, 255);  // B, G, R
  mat.at<cv::Vec3b>(0, 1) = cv::Vec3b(10, 188, 1);
  mat.at<cv::Vec3b>(0, 2) = cv::Vec3b(64, 64, 64);
  const std::string path = dir.Join("srgb8.png");
  ASSERT_TRUE(cv::imwrite(path, mat));

  Image image;
  ASSERT_TRUE(ReadImage(path, &image).ok());
  ASSERT_EQ(image.channels, 3);
  ASSERT_EQ(image.width, 3);
  EXPECT_NEAR(image.at(0, 0, 0), 1.0f, 1e-6);                   // R = 255
  EXPECT_NEAR(image.at(0, 0, 1), 0.2158605f, 1e-6);             // G = 128
  EXPECT_NEAR(image.at(0, 0, 2), 0.0f, 1e-6);                   // B = 0
  EXPECT_NEAR(image.at(1, 0, 0), SrgbDecode(1 / 255.0), 1e-7);  // linear segment
  EXPECT_NEAR(image.at(1, 0, 1), SrgbDecode(188 / 255.0), 1e-6);
  EXPECT_NEAR(image.at(1, 0, 2), SrgbDecode(10 / 255.0), 1e-6);

  Image raw;
  ASSERT_TRUE(ReadImage(path, &raw, /*srgb=*/false).ok());
  EXPECT_NEAR(raw.at(0, 0, 1), 128 / 255.0f, 1e-7);
  EXPECT_NEAR(raw.at(1, 0, 2), 10 / 255.0f, 1e-7);
}

TEST(ImageIoPng, Reads16BitWithSrgbDecode) {
  TempDir dir;
  cv::Mat mat(1, 2, CV_16UC4);
  mat.at<cv::Vec4w>(0, 0) = cv::Vec4w(0, 32768, 65535, 32768);  // B, G, R, A
  mat.at<cv::Vec4w>(0, 1) = cv::Vec4w(1000, 50000, 7, 65535);
  const std::string path = dir.Join("srgb16.png");
  ASSERT_TRUE(cv::imwrite(path, mat));

  Image image;
  ASSERT_TRUE(ReadImage(path, &image).ok());
  ASSERT_EQ(image.channels, 4);
  EXPECT_NEAR(image.at(0, 0, 0), 1.0f, 1e-6);
  EXPECT_NEAR(image.at(0, 0, 1), 0.21404f, 1e-5);  // sRGB 0.5 -> 0.21404
  EXPECT_NEAR(image.at(0, 0, 2), 0.0f, 1e-7);
  EXPECT_NEAR(image.at(0, 0, 3), 32768 / 65535.0f, 1e-7);  // alpha is not decoded.
  EXPECT_NEAR(image.at(1, 0, 0), SrgbDecode(7 / 65535.0), 1e-8);
  EXPECT_NEAR(image.at(1, 0, 1), SrgbDecode(50000 / 65535.0), 1e-6);
  EXPECT_NEAR(image.at(1, 0, 2), SrgbDecode(1000 / 65535.0), 1e-6);
  EXPECT_NEAR(image.at(1, 0, 3), 1.0f, 1e-7);
}

TEST(ImageIoPng, ReadsGreyscaleAsOneChannel) {
  TempDir dir;
  cv::Mat mat(2, 1, CV_8UC1);
  mat.at<uint8_t>(0, 0) = 128;
  mat.at<uint8_t>(1, 0) = 255;
  const std::string path = dir.Join("grey.png");
  ASSERT_TRUE(cv::imwrite(path, mat));
  Image image;
  ASSERT_TRUE(ReadImage(path, &image).ok());
  EXPECT_EQ(image.channels, 1);
  EXPECT_EQ(image.width, 1);
  EXPECT_EQ(image.height, 2);
  EXPECT_NEAR(image.at(0, 0), 0.2158605f, 1e-6);
  EXPECT_NEAR(image.at(0, 1), 1.0f, 1e-6);
}

TEST(ImageIoPng, GreyAlphaBecomesRgba) {
  // A 2x1 8-bit grey+alpha PNG (colour type 4): (grey 128, alpha 255), (grey 0, alpha 64).
  const unsigned char kPng[] = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
      0x44, 0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x04, 0x00, 0x00,
      0x00, 0x5e, 0x2b, 0xb7, 0x01, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x44, 0x41, 0x54, 0x78,
      0x9c, 0x63, 0x68, 0xf8, 0xcf, 0xe0, 0x00, 0x00, 0x05, 0x42, 0x01, 0xc0, 0x8b, 0x64,
      0x52, 0x50, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  TempDir dir;
  const std::string path = dir.Join("grey_alpha.png");
  testing::WriteTestFile(path, std::string(reinterpret_cast<const char*>(kPng), sizeof(kPng)));
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(image.channels, 4);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(image.at(0, 0, c), 0.2158605f, 1e-6);
  EXPECT_NEAR(image.at(0, 0, 3), 1.0f, 1e-6);
  EXPECT_NEAR(image.at(1, 0, 0), 0.0f, 1e-6);
  EXPECT_NEAR(image.at(1, 0, 3), 64 / 255.0f, 1e-6);
}

TEST(ImageIoPng, WriteThenReadRoundTrip) {
  TempDir dir;
  Image image(4, 2, 4);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = (i % 11) / 10.0f;
  image.at(0, 0, 0) = 2.0f;                                     // clamped to 1
  image.at(1, 0, 1) = -1.0f;                                    // clamped to 0
  image.at(2, 0, 2) = std::numeric_limits<float>::quiet_NaN();  // written as 0
  const std::string path = dir.Join("out.png");
  ASSERT_TRUE(WritePng(path, image).ok());

  // The file holds sRGB codes in BGRA order.
  cv::Mat mat = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(mat.type(), CV_8UC4);
  EXPECT_EQ(mat.at<cv::Vec4b>(0, 0)[2], 255);
  EXPECT_EQ(mat.at<cv::Vec4b>(0, 1)[1], 0);
  EXPECT_EQ(mat.at<cv::Vec4b>(0, 2)[0], 0);

  Image read;
  ASSERT_TRUE(ReadImage(path, &read).ok());
  ASSERT_EQ(read.channels, 4);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 4; ++c) {
        float expected = image.at(x, y, c);
        expected = std::isnan(expected) ? 0.0f : std::min(std::max(expected, 0.0f), 1.0f);
        if (c < 3) {
          // Quantization is uniform in sRGB space: compare there.
          EXPECT_NEAR(LinearToSrgb(read.at(x, y, c)), LinearToSrgb(expected), 0.5f / 255 + 1e-6)
              << x << "," << y << "," << c;
        } else {
          EXPECT_NEAR(read.at(x, y, c), expected, 0.5f / 255 + 1e-6);  // alpha stays linear.
        }
      }
    }
  }
}

TEST(ImageIoPng, WriteWithoutSrgbStoresValues) {
  TempDir dir;
  Image image(2, 1, 1);
  image.data = {0.5f, 0.25f};
  const std::string path = dir.Join("data.png");
  ASSERT_TRUE(WritePng(path, image, /*srgb=*/false).ok());
  cv::Mat mat = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(mat.type(), CV_8UC1);
  EXPECT_EQ(mat.at<uint8_t>(0, 0), 128);
  EXPECT_EQ(mat.at<uint8_t>(0, 1), 64);
}

TEST(ImageIoMask, ThresholdsFirstChannelAt127) {
  TempDir dir;
  cv::Mat mat(1, 4, CV_8UC3, cv::Scalar(0, 0, 0));
  const uint8_t red[] = {0, 127, 128, 255};
  for (int x = 0; x < 4; ++x) mat.at<cv::Vec3b>(0, x) = cv::Vec3b(255, 255, red[x]);
  const std::string path = dir.Join("mask.png");
  ASSERT_TRUE(cv::imwrite(path, mat));
  Image mask;
  ASSERT_TRUE(ReadMask(path, &mask).ok());
  ASSERT_EQ(mask.channels, 1);
  EXPECT_EQ(mask.data, (std::vector<float>{0, 0, 1, 1}));
}

TEST(ImageIoErrors, MissingFileNamesPath) {
  TempDir dir;
  const std::string path = dir.Join("nothing_here.png");
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path));
  EXPECT_THAT(status.message(), HasSubstr("not found"));
  EXPECT_FALSE(ReadMask(path, &image).ok());
  EXPECT_FALSE(ReadImage(dir.Join("missing.exr"), &image).ok());
}

TEST(ImageIoErrors, UnsupportedExtensionNamesPath) {
  TempDir dir;
  const std::string path = dir.Join("photo.jpg");
  testing::WriteTestFile(path, "x");
  Image image;
  Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path));
  EXPECT_THAT(status.message(), HasSubstr("extension"));
  status = WriteImage(dir.Join("out.tif"), Image(2, 2, 3));
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("out.tif"));
}

TEST(ImageIoErrors, CorruptPngNamesPath) {
  TempDir dir;
  const std::string path = dir.Join("corrupt.png");
  testing::WriteTestFile(path, "\x89PNG\r\n\x1a\n garbage garbage");
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path));
}

TEST(ImageIoErrors, DirectoryIsNotAnImage) {
  TempDir dir;
  const std::string path = dir.Join("folder.png");
  std::filesystem::create_directory(path);
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path));
}

TEST(ImageIoErrors, BadImagesAreNotWritten) {
  TempDir dir;
  EXPECT_FALSE(WriteExr(dir.Join("two.exr"), Image(2, 2, 2)).ok());
  EXPECT_FALSE(WritePng(dir.Join("two.png"), Image(2, 2, 2)).ok());
  const Status status = WriteExr(dir.Join("empty.exr"), Image());
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("empty.exr"));
  EXPECT_THAT(ListDir(dir.path()), SizeIs(0));  // no half-written or temporary files.
}

TEST(ImageIoErrors, UnwritableLocationNamesPath) {
  TempDir dir;
  testing::WriteTestFile(dir.Join("file"), "x");
  const std::string path = dir.Join("file/sub/out.exr");  // parent is a regular file.
  const Status status = WriteExr(path, Image(2, 2, 3));
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("file")));
}

// DecodeImage (the fuzzed entry point) is ReadImage without the file read, for EXR and PNG.
TEST(ImageIoDecode, MatchesReadImage) {
  for (const std::string name : {"/cycles/bunny_point_diffuse/images/000.exr",
                                 "/cycles/bunny_point_diffuse/masks/000.png"}) {
    const std::string path = DataDir() + name;
    std::ifstream in(path, std::ios::binary);
    const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Image from_file, from_buffer;
    ASSERT_TRUE(ReadImage(path, &from_file).ok());
    const Status status = DecodeImage(data, path, &from_buffer);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(from_buffer.width, from_file.width);
    EXPECT_EQ(from_buffer.height, from_file.height);
    EXPECT_EQ(from_buffer.channels, from_file.channels);
    EXPECT_EQ(from_buffer.data, from_file.data);
  }
  Image image;
  for (const std::string name : {"empty.png", "empty.exr"}) {
    const Status status = DecodeImage("", name, &image);
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), ::testing::StartsWith(name + ": "));
  }
}

// Found by exr_fuzzer (data/fuzz_regressions/): corrupt pixel data in a scanline EXR. tinyexr
// 1.0.1 leaks its channel planes on this failure (fuzz/lsan.supp); the reader's answer is one
// error line naming the file (tinyexr's message ended in a newline: now replaced), and no crash.
TEST(ImageIoFuzzRegression, CorruptExrPixelsNameTheFile) {
  const std::string path = DataDir() + "/fuzz_regressions/exr_tinyexr_decode_leak.exr";
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::StartsWith(path + ": cannot read OpenEXR pixels"));
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
}

// Found by exr_fuzzer (data/fuzz_regressions/): a 5.7 kB EXR whose data window is 8323073x128
// pixels made tinyexr allocate 17 GB before decoding; the header's size is now checked first.
TEST(ImageIoFuzzRegression, HugeExrDataWindowIsRejectedBeforeDecoding) {
  const std::string path = DataDir() + "/fuzz_regressions/exr_huge_data_window.exr";
  Image image;
  const Status status = ReadImage(path, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::StartsWith(path + ": OpenEXR data window 8323073x128"));
  EXPECT_THAT(status.message(), HasSubstr("too large"));
}

}  // namespace
}  // namespace sft
