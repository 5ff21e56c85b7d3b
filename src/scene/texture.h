// scene/texture.h — the built scene's textures as flat data: every
// texture node in one array (inputs refer to nodes by index, always lower
// ones, so evaluation recurses over a DAG without cycles), every image's
// texels in one contiguous buffer, each image once however many nodes use
// it. Evaluated at a hit's (u, v) and object-space point; a switch per
// node, no virtual calls, no allocation.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "math/vec.h"

namespace tdpm {

struct TexturePoint {
  Vec2f uv;
  Vec3f localP;  // object space (checker3d)
};

struct TextureImage {
  int width = 0, height = 0;
  size_t offset = 0;  // first texel in TextureSet::texels, row 0 at the top
};

struct TexNodeInput {
  int32_t node = -1;  // < 0: the constant
  Rgb value{1.0f};
};

struct TextureNode {
  enum class Kind : uint8_t { Constant, Image, Scale, Mix, Checkerboard, Checker3D };
  enum class Wrap : uint8_t { Repeat, Clamp, Black };
  Kind kind = Kind::Constant;
  Wrap wrap = Wrap::Repeat;
  bool bilinear = true;
  bool invert = false;
  bool firstChannel = false;  // float image texture: R = G = B = the first channel
  float uscale = 1, vscale = 1, udelta = 0, vdelta = 0;
  float scale = 1;
  float invCell = 1;
  uint32_t image = 0;
  TexNodeInput a, b, amount;
};

class TextureSet {
 public:
  std::vector<TextureNode> nodes;
  std::vector<TextureImage> images;
  std::vector<Rgb> texels;

  Rgb eval(uint32_t node, const TexturePoint& p) const;
  // Bounds on the first channel of eval(node, p) over every p: from the
  // constants and each image's texels (bilinear lookups are convex
  // combinations of them), through the node tree; conservative, not tight
  // (a mix's bound takes its inputs' independently). Classifies a material
  // with a textured roughness (scene/build.cpp).
  void range(uint32_t node, float* lo, float* hi) const;
  // One texel with the wrap mode applied (Black outside: 0).
  Rgb texel(const TextureImage& im, TextureNode::Wrap wrap, int x, int y) const;
  // pbrt's lookup of image st (st in [0,1]^2, t = 0 at the bottom row):
  // bilinear between the four texel centres around it, or the nearest.
  Rgb lookup(const TextureImage& im, TextureNode::Wrap wrap, bool bilinear, float s, float t) const;

 private:
  void inputRange(const TexNodeInput& in, float* lo, float* hi) const {
    if (in.node < 0) *lo = *hi = in.value.r;
    else range(uint32_t(in.node), lo, hi);
  }
  Rgb input(const TexNodeInput& in, const TexturePoint& p) const {
    return in.node < 0 ? in.value : eval(uint32_t(in.node), p);
  }
};

}  // namespace tdpm
