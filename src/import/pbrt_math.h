// import/pbrt_math.h — the transforms of a pbrt file in double precision:
// pbrt's statements (Translate, Rotate, Scale, LookAt, Transform) as affine
// matrices, and the decomposition of a matrix into tdpm's T * R * S pose.
#pragma once
#include <optional>
#include <string>

#include "math/transform.h"
#include "math/vec.h"

namespace tdpm::pbrt {

struct Mat {
  double m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

  Mat operator*(const Mat& b) const;
  bool operator==(const Mat& b) const;
  bool operator!=(const Mat& b) const { return !(*this == b); }
  bool isAffine() const { return m[3][0] == 0 && m[3][1] == 0 && m[3][2] == 0 && m[3][3] == 1; }
  double det3() const;
  std::optional<Mat> inverse() const;  // affine only; none when singular
  Vec3f point(Vec3f p) const;
  Vec3f vector(Vec3f v) const;
  Vec3f normal(Vec3f n) const;  // inverse transpose (object-space outward stays outward)
  Affine3f toAffine() const;

  static Mat translate(double x, double y, double z);
  static Mat scale(double x, double y, double z);
  static Mat rotate(double degrees, double x, double y, double z);  // right-handed about the axis
};

// pbrt's LookAt: the world-to-camera matrix of a left-handed camera frame
// (camera +x = normalize(up x dir)). Empty when the frame is degenerate.
std::optional<Mat> lookAt(Vec3f eye, Vec3f look, Vec3f up);

// M = T * R * diag(s): R a proper rotation, s may have negative components.
// Empty when the linear part has shear or a zero axis (not representable).
struct Pose {
  Vec3f translate;
  Quaternion rotate;
  Vec3f scale{1, 1, 1};
};
std::optional<Pose> decompose(const Mat& m);
// Why `m` cannot be a placement even before shear is asked about: empty
// when every axis's scale factor (column length) is a finite number in
// [scene::limits::kMinScale, kMaxScale], else e.g. "it scales an axis by
// 1e-30, which is degenerate (tdpm needs scale factors in [1e-12, 1e12])".
std::string scaleProblem(const Mat& m);

Quaternion quaternionFromMatrix(const double r[3][3]);

// The mirror x -> -x that turns pbrt's left-handed camera into tdpm's
// right-handed one (see docs/pbrt-import.md, "Handedness").
Mat mirrorX();
// The same mirror applied to a pose: W * T R S = T(Wt) * (W R W) * (W S).
Pose mirrorPose(const Pose& p);

}  // namespace tdpm::pbrt
