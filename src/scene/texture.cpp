// scene/texture.cpp — texture evaluation (see texture.h). Lookups follow
// pbrt-v4's Image::Bilerp / LookupNearest: texel centres at (i + 1/2) / res,
// the image's row 0 at t = 1.
#include "scene/texture.h"

#include <algorithm>

namespace tdpm {

Rgb TextureSet::texel(const TextureImage& im, TextureNode::Wrap wrap, int x, int y) const {
  switch (wrap) {
    case TextureNode::Wrap::Repeat:
      x %= im.width;
      y %= im.height;
      if (x < 0) x += im.width;
      if (y < 0) y += im.height;
      break;
    case TextureNode::Wrap::Clamp:
      x = std::clamp(x, 0, im.width - 1);
      y = std::clamp(y, 0, im.height - 1);
      break;
    case TextureNode::Wrap::Black:
      if (x < 0 || y < 0 || x >= im.width || y >= im.height) return Rgb(0.0f);
      break;
  }
  return texels[im.offset + size_t(y) * size_t(im.width) + size_t(x)];
}

Rgb TextureSet::lookup(const TextureImage& im, TextureNode::Wrap wrap, bool bilinear, float s, float t) const {
  // Image space: x right, y down from the top row (pbrt flips t).
  float x = s * float(im.width), y = (1.0f - t) * float(im.height);
  // Far outside float precision of a texel: no meaningful position.
  if (!(std::fabs(x) < 1e9f && std::fabs(y) < 1e9f)) return Rgb(0.0f);
  if (!bilinear) return texel(im, wrap, int(std::floor(x)), int(std::floor(y)));
  x -= 0.5f;
  y -= 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  int xi = int(fx), yi = int(fy);
  float dx = x - fx, dy = y - fy;
  return texel(im, wrap, xi, yi) * ((1 - dx) * (1 - dy)) + texel(im, wrap, xi + 1, yi) * (dx * (1 - dy)) +
         texel(im, wrap, xi, yi + 1) * ((1 - dx) * dy) + texel(im, wrap, xi + 1, yi + 1) * (dx * dy);
}

Rgb TextureSet::eval(uint32_t index, const TexturePoint& p) const {
  const TextureNode& n = nodes[index];
  switch (n.kind) {
    case TextureNode::Kind::Constant: return n.a.value;
    case TextureNode::Kind::Image: {
      float s = n.uscale * p.uv.x + n.udelta, t = n.vscale * p.uv.y + n.vdelta;
      Rgb v = lookup(images[n.image], n.wrap, n.bilinear, s, t);
      if (n.firstChannel) v = Rgb(v.r);
      v = v * n.scale;
      if (n.invert) v = Rgb(std::max(0.0f, 1 - v.r), std::max(0.0f, 1 - v.g), std::max(0.0f, 1 - v.b));
      return v;
    }
    case TextureNode::Kind::Scale: return input(n.a, p) * input(n.b, p);
    case TextureNode::Kind::Mix: {
      float t = input(n.amount, p).r;
      return input(n.a, p) * (1 - t) + input(n.b, p) * t;
    }
    case TextureNode::Kind::Checkerboard: {
      float s = n.uscale * p.uv.x + n.udelta, t = n.vscale * p.uv.y + n.vdelta;
      bool odd = (int64_t(std::floor(s)) + int64_t(std::floor(t))) & 1;
      return odd ? input(n.b, p) : input(n.a, p);
    }
    case TextureNode::Kind::Checker3D: {
      // As the inline "checker" (material.h): cells centred on the origin.
      int64_t ix = int64_t(std::floor(p.localP.x * n.invCell + 0.5f));
      int64_t iy = int64_t(std::floor(p.localP.y * n.invCell + 0.5f));
      int64_t iz = int64_t(std::floor(p.localP.z * n.invCell + 0.5f));
      return ((ix + iy + iz) & 1) ? input(n.b, p) : input(n.a, p);
    }
  }
  return Rgb(0.0f);
}

void TextureSet::range(uint32_t index, float* lo, float* hi) const {
  const TextureNode& n = nodes[index];
  float al, ah, bl, bh;
  switch (n.kind) {
    case TextureNode::Kind::Constant: *lo = *hi = n.a.value.r; return;
    case TextureNode::Kind::Image: {
      const TextureImage& im = images[n.image];
      // Black wrap and lookups beyond float precision give 0.
      float l = 0, h = 0;
      bool first = n.wrap != TextureNode::Wrap::Black;
      for (size_t i = 0; i < size_t(im.width) * size_t(im.height); ++i) {
        float v = texels[im.offset + i].r;
        l = first ? v : std::min(l, v);
        h = first ? v : std::max(h, v);
        first = false;
      }
      l = std::min(l * n.scale, h * n.scale);  // scale >= 0 (checked on input), but keep the order
      h = std::max(l, h * n.scale);
      if (n.invert) {
        float il = std::max(0.0f, 1 - h), ih = std::max(0.0f, 1 - l);
        l = il;
        h = ih;
      }
      *lo = l;
      *hi = h;
      return;
    }
    case TextureNode::Kind::Scale: {
      inputRange(n.a, &al, &ah);
      inputRange(n.b, &bl, &bh);
      float c[4] = {al * bl, al * bh, ah * bl, ah * bh};
      *lo = std::min(std::min(c[0], c[1]), std::min(c[2], c[3]));
      *hi = std::max(std::max(c[0], c[1]), std::max(c[2], c[3]));
      return;
    }
    case TextureNode::Kind::Mix: {
      // (1 - t) a + t b is linear in each of a, b, t: extremes at the box's corners.
      float tl, th;
      inputRange(n.a, &al, &ah);
      inputRange(n.b, &bl, &bh);
      inputRange(n.amount, &tl, &th);
      *lo = INFINITY;
      *hi = -INFINITY;
      for (float a : {al, ah})
        for (float b : {bl, bh})
          for (float t : {tl, th}) {
            float v = a * (1 - t) + b * t;
            *lo = std::min(*lo, v);
            *hi = std::max(*hi, v);
          }
      return;
    }
    case TextureNode::Kind::Checkerboard:
    case TextureNode::Kind::Checker3D:
      inputRange(n.a, &al, &ah);
      inputRange(n.b, &bl, &bh);
      *lo = std::min(al, bl);
      *hi = std::max(ah, bh);
      return;
  }
  *lo = *hi = 0;
}

}  // namespace tdpm
