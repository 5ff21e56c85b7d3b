// math/transform.h — affine transforms (3x4, row-major) and unit
// quaternions. lerp() of two Affine3f is the component-wise blend Embree
// applies between motion time steps, which motion/ relies on.
#pragma once
#include <cmath>

#include "math/vec.h"

namespace tdpm {

struct Quaternion {
  float w = 1, x = 0, y = 0, z = 0;

  static Quaternion fromAxisAngle(Vec3f axis, float radians) {
    Vec3f a = normalize(axis);
    float s = std::sin(0.5f * radians);
    return {std::cos(0.5f * radians), a.x * s, a.y * s, a.z * s};
  }
  float dot(const Quaternion& o) const { return w * o.w + x * o.x + y * o.y + z * o.z; }
  Quaternion operator*(const Quaternion& o) const {
    return {w * o.w - x * o.x - y * o.y - z * o.z, w * o.x + x * o.w + y * o.z - z * o.y,
            w * o.y - x * o.z + y * o.w + z * o.x, w * o.z + x * o.y - y * o.x + z * o.w};
  }
  // Rotation angle (radians, in [0, pi]) between two orientations.
  float angleTo(const Quaternion& o) const {
    float d = std::fabs(dot(o));
    return 2.0f * std::acos(std::min(1.0f, d));
  }
};

// Spherical linear interpolation along the shorter arc.
inline Quaternion slerp(Quaternion a, Quaternion b, float t) {
  float d = a.dot(b);
  if (d < 0) { b = {-b.w, -b.x, -b.y, -b.z}; d = -d; }
  float wa, wb;
  if (d > 0.9995f) {  // nearly parallel: lerp then normalise
    wa = 1.0f - t; wb = t;
  } else {
    float theta = std::acos(d), s = std::sin(theta);
    wa = std::sin((1.0f - t) * theta) / s;
    wb = std::sin(t * theta) / s;
  }
  Quaternion q{wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z};
  float n = std::sqrt(q.dot(q));
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

struct Affine3f {
  // Row-major 3x4: p' = M[:, 0:3] p + M[:, 3].
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  static Affine3f identity() { return {}; }
  static Affine3f translate(Vec3f t) {
    Affine3f a; a.m[0][3] = t.x; a.m[1][3] = t.y; a.m[2][3] = t.z; return a;
  }
  static Affine3f scale(Vec3f s) {
    Affine3f a; a.m[0][0] = s.x; a.m[1][1] = s.y; a.m[2][2] = s.z; return a;
  }
  static Affine3f rotate(const Quaternion& q) {
    Affine3f a;
    float w = q.w, x = q.x, y = q.y, z = q.z;
    a.m[0][0] = 1 - 2 * (y * y + z * z); a.m[0][1] = 2 * (x * y - w * z); a.m[0][2] = 2 * (x * z + w * y);
    a.m[1][0] = 2 * (x * y + w * z); a.m[1][1] = 1 - 2 * (x * x + z * z); a.m[1][2] = 2 * (y * z - w * x);
    a.m[2][0] = 2 * (x * z - w * y); a.m[2][1] = 2 * (y * z + w * x); a.m[2][2] = 1 - 2 * (x * x + y * y);
    return a;
  }
  // T * R * S: scale first, then rotate, then translate.
  static Affine3f fromTRS(Vec3f t, const Quaternion& r, Vec3f s) {
    return translate(t) * rotate(r) * scale(s);
  }

  Affine3f operator*(const Affine3f& b) const {
    Affine3f c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) {
        float v = m[i][0] * b.m[0][j] + m[i][1] * b.m[1][j] + m[i][2] * b.m[2][j];
        c.m[i][j] = v + (j == 3 ? m[i][3] : 0.0f);
      }
    return c;
  }
  Vec3f point(Vec3f p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3f vector(Vec3f v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  Vec3f translation() const { return {m[0][3], m[1][3], m[2][3]}; }
  float determinant3() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  Affine3f inverse() const {
    float d = determinant3();
    float id = 1.0f / d;
    Affine3f r;
    r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * id;
    r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
    r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
    r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * id;
    r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
    r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
    r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * id;
    r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
    r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
    Vec3f t = r.vector(translation());
    r.m[0][3] = -t.x; r.m[1][3] = -t.y; r.m[2][3] = -t.z;
    return r;
  }
  // Normals transform by the inverse transpose.
  Vec3f normal(Vec3f n) const { return inverse().transposedVector(n); }
  // The 3x3 part's transpose times v: a normal's transform when this is the
  // inverse placement (as normal(), without its inverse per call).
  Vec3f transposedVector(Vec3f v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z,
            m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
};

// Component-wise blend, exactly as Embree interpolates between time steps.
inline Affine3f lerp(const Affine3f& a, const Affine3f& b, float t) {
  Affine3f r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = (1.0f - t) * a.m[i][j] + t * b.m[i][j];
  return r;
}

}  // namespace tdpm
