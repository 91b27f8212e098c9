// Image files. EXR (tinyexr) holds linear values as stored; PNG (OpenCV) 8- or 16-bit is
// sRGB-encoded and decoded to linear on read unless `srgb` is false (masks, data textures).
#ifndef SFT_IMAGE_IMAGE_IO_H_
#define SFT_IMAGE_IMAGE_IO_H_

#include <string>

#include "src/core/image.h"
#include "src/core/status.h"

namespace sft {

// sRGB transfer functions (IEC 61966-2-1), on [0, 1].
float SrgbToLinear(float v);
float LinearToSrgb(float v);

// Reads .exr or .png (by extension, case-insensitive). Channels as stored (1, 3 or 4; a 2-channel
// grey+alpha PNG becomes 4-channel RGBA). For PNG, colour channels are sRGB-decoded when `srgb`;
// alpha is never decoded. Errors name the path: missing, unreadable, unsupported extension, an EXR
// data window over 65536 pixels a side or over 2 GiB of decoded 32-bit values.
Status ReadImage(const std::string& path, Image* image, bool srgb = true);

// Decodes the contents of an .exr or .png file held in memory (`data`), as ReadImage does;
// `path` selects the format by its extension and names the file in errors.
Status DecodeImage(const std::string& data, const std::string& path, Image* image,
                   bool srgb = true);
// Reads a mask PNG: 1 channel, 1.0 where the first channel > 127 (of 255), else 0.0.
Status ReadMask(const std::string& path, Image* mask);

// Writes a float EXR (32-bit, channels 1/3/4), atomically.
Status WriteExr(const std::string& path, const Image& image);
// Writes an 8-bit PNG, sRGB-encoding colour channels when `srgb`, clamping to [0, 1], atomically.
Status WritePng(const std::string& path, const Image& image, bool srgb = true);
// The same PNG file's bytes in memory (for containers such as glTF binaries). Error on an empty
// image or a channel count other than 1, 3 or 4.
Status EncodePng(const Image& image, bool srgb, std::string* bytes);
// Writes by extension (.exr or .png).
Status WriteImage(const std::string& path, const Image& image);

}  // namespace sft

#endif  // SFT_IMAGE_IMAGE_IO_H_
