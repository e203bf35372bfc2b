// A segmented frame's layers (the CUDA executor cuts rays into segments marched by separate
// threads, each into its own layer) and their front-to-back composite: written once, used by the
// executor's composite kernel and by the CUDA blend into a window's framebuffer (DeviceImageCopy),
// which reads the layers directly when the flat image is not needed.
#pragma once
#include "../Math.h"

namespace spaceskip {

/// The layers of a segmented frame, device memory. Layer k holds segment k of every pixel's ray
/// (k = 0 nearest the eye): pixel (x, y) at [(k * height + y) * width + x].
struct SegmentLayersView {
  const vec4f* layers = nullptr;         ///< premultiplied RGBA; nullptr: no layers
  const unsigned char* flags = nullptr;  ///< same index: 1 the segment coloured the pixel, 0 it did not
                                         ///< (its layer was not written: (0, 0, 0, 0)); nullptr: all written
  int segments = 0;
  int width = 0, height = 0;
  int rect[4] = {0, 0, 0, 0};  ///< x0, y0, x1, y1 (half-open): the pixels marched; outside, (0, 0, 0, 0)
};

/// Pixel (x, y) of the frame: its layers composited front to back ("over"). Layers a segment left
/// empty are skipped: "over" with (0, 0, 0, 0) leaves the colour bit for bit as it was, so the
/// result equals compositing every layer.
SS_FUNC vec4f compositeLayers(const SegmentLayersView& v, int x, int y) {
  if (x < v.rect[0] || x >= v.rect[2] || y < v.rect[1] || y >= v.rect[3]) return vec4f{0, 0, 0, 0};
  const int64_t pixels = int64_t(v.width) * v.height, i = int64_t(y) * v.width + x;
  int k = v.segments - 1;
  if (v.flags)
    while (k >= 0 && !v.flags[int64_t(k) * pixels + i]) --k;
  if (k < 0) return vec4f{0, 0, 0, 0};
  vec4f c = v.layers[int64_t(k) * pixels + i];
  for (--k; k >= 0; --k) {
    if (v.flags && !v.flags[int64_t(k) * pixels + i]) continue;
    const vec4f l = v.layers[int64_t(k) * pixels + i];
    const float keep = 1.f - l.w;
    c = vec4f{l.x + keep * c.x, l.y + keep * c.y, l.z + keep * c.z, l.w + keep * c.w};
  }
  return c;
}

}  // namespace spaceskip
