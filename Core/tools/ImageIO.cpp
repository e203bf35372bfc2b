// PNG via libpng; image metrics.
#include "spaceskip/ImageIO.h"

#include "spaceskip/OutputFile.h"

#ifdef SPACESKIP_HAVE_PNG
#include <png.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>

namespace spaceskip {

namespace {
[[maybe_unused]] unsigned char to8(float v) { return (unsigned char)std::lround(std::clamp(v, 0.f, 1.f) * 255.f); }

/// n zeroed bytes, or an error naming what they were for, their count and the image's size.
[[maybe_unused]] std::vector<unsigned char> allocatingBytes(size_t n, const char* what, const Image& img) {
  try {
    return std::vector<unsigned char>(n);
  } catch (const std::bad_alloc&) {
    throw std::runtime_error("out of memory allocating " + std::string(what) + " of a " + std::to_string(img.width) +
                             "x" + std::to_string(img.height) + " image (" + std::to_string(n) + " bytes)");
  }
}
}  // namespace

std::string encodePng(const Image& img, bool overBlack) {
  if (img.width <= 0 || img.height <= 0) throw std::invalid_argument("empty image");
#ifndef SPACESKIP_HAVE_PNG
  (void)overBlack;
  throw std::runtime_error("cannot write PNG: SpaceSkip was built without libpng");
#else
  std::vector<unsigned char> rows = allocatingBytes(size_t(img.width) * img.height * 4, "the PNG's 8-bit pixels", img);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const vec4f& p = img.rgba[size_t(y) * img.width + x];
      unsigned char* o = &rows[(size_t(img.height - 1 - y) * img.width + x) * 4];
      if (overBlack) {
        o[0] = to8(p.x); o[1] = to8(p.y); o[2] = to8(p.z); o[3] = 255;
      } else {
        // PNG stores straight alpha.
        float a = p.w;
        o[0] = to8(a > 0 ? p.x / a : 0); o[1] = to8(a > 0 ? p.y / a : 0); o[2] = to8(a > 0 ? p.z / a : 0);
        o[3] = to8(a);
      }
    }
  png_image pi{};
  pi.version = PNG_IMAGE_VERSION;
  pi.width = png_uint_32(img.width);
  pi.height = png_uint_32(img.height);
  pi.format = PNG_FORMAT_RGBA;
  // Encoded in memory: libpng's png_image_write_to_file removes its file on an error, which
  // would delete the user's path (a device node, a symbolic link); OutputFile writes it.
  png_alloc_size_t bytes = 0;
  if (!png_image_write_get_memory_size(pi, bytes, 0, rows.data(), 0, nullptr))
    throw std::runtime_error(std::string("cannot encode PNG (") + pi.message + ")");
  std::vector<unsigned char> encoded = allocatingBytes(size_t(bytes), "the encoded PNG", img);
  if (!png_image_write_to_memory(&pi, encoded.data(), &bytes, 0, rows.data(), 0, nullptr))
    throw std::runtime_error(std::string("cannot encode PNG (") + pi.message + ")");
  return std::string(reinterpret_cast<const char*>(encoded.data()), size_t(bytes));
#endif
}

void savePng(const Image& img, const std::string& path, bool overBlack) {
  try {
    writeOutputFile(path, encodePng(img, overBlack));
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.compare(0, path.size() + 1, path + ":") == 0) throw;
    throw std::runtime_error(path + ": " + what);
  }
}

Image loadPng(const std::string& path) {
#ifndef SPACESKIP_HAVE_PNG
  throw std::runtime_error(path + ": cannot read PNG: SpaceSkip was built without libpng");
#else
  png_image pi{};
  pi.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&pi, path.c_str()))
    throw std::runtime_error(path + ": cannot read PNG (" + pi.message + ")");
  pi.format = PNG_FORMAT_RGBA;
  std::vector<unsigned char> buf(PNG_IMAGE_SIZE(pi));
  if (!png_image_finish_read(&pi, nullptr, buf.data(), 0, nullptr))
    throw std::runtime_error(path + ": cannot decode PNG (" + pi.message + ")");
  Image img;
  img.width = int(pi.width);
  img.height = int(pi.height);
  img.rgba.resize(size_t(img.width) * img.height);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const unsigned char* s = &buf[(size_t(img.height - 1 - y) * img.width + x) * 4];
      float a = s[3] / 255.f;
      img.rgba[size_t(y) * img.width + x] = vec4f{s[0] / 255.f * a, s[1] / 255.f * a, s[2] / 255.f * a, a};
    }
  return img;
#endif
}

ImageDiff compareImages(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) throw std::invalid_argument("image sizes differ");
  ImageDiff d;
  double se = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i) {
    const float da[4] = {a.rgba[i].x - b.rgba[i].x, a.rgba[i].y - b.rgba[i].y, a.rgba[i].z - b.rgba[i].z,
                         a.rgba[i].w - b.rgba[i].w};
    float m = 0;
    for (float v : da) {
      float av = std::fabs(v);
      if (!(av == av)) av = 1.f;  // NaN counts as a full difference
      m = std::max(m, av);
      se += double(av) * av;
    }
    d.maxAbs = std::max(d.maxAbs, m);
    if (m > 1.f / 255.f) ++d.differing;
  }
  double mse = se / double(a.rgba.size() * 4);
  d.psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
  return d;
}

double ssim(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) throw std::invalid_argument("image sizes differ");
  auto lum = [](const vec4f& p) { return 0.299 * p.x + 0.587 * p.y + 0.114 * p.z; };
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  double sum = 0;
  int64_t windows = 0;
  for (int y0 = 0; y0 + 8 <= a.height; y0 += 4)
    for (int x0 = 0; x0 + 8 <= a.width; x0 += 4) {
      double ma = 0, mb = 0, va = 0, vb = 0, cov = 0;
      for (int y = y0; y < y0 + 8; ++y)
        for (int x = x0; x < x0 + 8; ++x) {
          double pa = lum(a.rgba[size_t(y) * a.width + x]), pb = lum(b.rgba[size_t(y) * b.width + x]);
          ma += pa; mb += pb; va += pa * pa; vb += pb * pb; cov += pa * pb;
        }
      ma /= 64; mb /= 64;
      va = va / 64 - ma * ma; vb = vb / 64 - mb * mb; cov = cov / 64 - ma * mb;
      sum += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
      ++windows;
    }
  return windows ? sum / double(windows) : 1.0;
}

bool hasNonFinite(const Image& img) {
  for (const auto& p : img.rgba)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.w)) return true;
  return false;
}

}  // namespace spaceskip
