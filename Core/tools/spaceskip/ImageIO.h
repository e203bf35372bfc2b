// PNG output (libpng) and image comparison metrics.
#pragma once
#include "spaceskip/Types.h"

#include <string>

namespace spaceskip {

/// Premultiplied RGBA as an 8-bit RGBA PNG file's bytes (top row first), optionally over black.
std::string encodePng(const Image& img, bool overBlack = false);
/// encodePng written to `path` through OutputFile: a failed write leaves what was there.
void savePng(const Image& img, const std::string& path, bool overBlack = false);
/// Reads an 8-bit RGB/RGBA PNG into a (straight-to-premultiplied is not applied) Image.
Image loadPng(const std::string& path);

struct ImageDiff {
  float maxAbs = 0;      ///< max per-channel difference in [0,1]
  double psnr = 0;       ///< dB over RGBA, inf when identical
  int64_t differing = 0; ///< pixels with any channel differing by more than 1/255
};
/// Compares two images of the same size (throws std::invalid_argument otherwise).
ImageDiff compareImages(const Image& a, const Image& b);
/// Mean SSIM of the luminance over 8x8 windows (Wang et al. 2004 constants), in [-1, 1].
double ssim(const Image& a, const Image& b);
/// True when any channel of any pixel is NaN or Inf.
bool hasNonFinite(const Image& img);

}  // namespace spaceskip
