// Synthetic images for tests of image measures.
#ifndef SFT_TESTS_TESTING_TEST_IMAGES_H_
#define SFT_TESTS_TESTING_TEST_IMAGES_H_

#include "src/core/image.h"

namespace sft {
namespace testing {

// A smooth but structured RGB pattern in [0.1, 0.9]; `shift` moves it by that many pixels in x.
Image SmoothPattern(int width, int height, int shift = 0);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_TEST_IMAGES_H_
