// import/pbrt_math.cpp — affine matrices and pose decomposition.
#include "import/pbrt_math.h"

#include <cmath>
#include <sstream>

#include "scene/limits.h"

namespace tdpm::pbrt {

namespace {
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
}

Mat Mat::operator*(const Mat& b) const {
  Mat c;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += m[i][k] * b.m[k][j];
      c.m[i][j] = s;
    }
  return c;
}

bool Mat::operator==(const Mat& b) const {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (m[i][j] != b.m[i][j]) return false;
  return true;
}

double Mat::det3() const {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

std::optional<Mat> Mat::inverse() const {
  double d = det3();
  if (!(std::fabs(d) > 1e-300) || !std::isfinite(d)) return std::nullopt;
  double id = 1.0 / d;
  Mat r;
  r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * id;
  r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
  r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
  r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * id;
  r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
  r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
  r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * id;
  r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
  r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
  for (int i = 0; i < 3; ++i)
    r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
  return r;
}

Vec3f Mat::point(Vec3f p) const {
  double r[3];
  for (int i = 0; i < 3; ++i) r[i] = m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3];
  return {float(r[0]), float(r[1]), float(r[2])};
}

Vec3f Mat::vector(Vec3f v) const {
  double r[3];
  for (int i = 0; i < 3; ++i) r[i] = m[i][0] * v.x + m[i][1] * v.y + m[i][2] * v.z;
  return {float(r[0]), float(r[1]), float(r[2])};
}

Vec3f Mat::normal(Vec3f n) const {
  std::optional<Mat> inv = inverse();
  if (!inv) return n;
  const auto& a = inv->m;
  return {float(a[0][0] * n.x + a[1][0] * n.y + a[2][0] * n.z), float(a[0][1] * n.x + a[1][1] * n.y + a[2][1] * n.z),
          float(a[0][2] * n.x + a[1][2] * n.y + a[2][2] * n.z)};
}

Affine3f Mat::toAffine() const {
  Affine3f a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) a.m[i][j] = float(m[i][j]);
  return a;
}

Mat Mat::translate(double x, double y, double z) {
  Mat t;
  t.m[0][3] = x;
  t.m[1][3] = y;
  t.m[2][3] = z;
  return t;
}

Mat Mat::scale(double x, double y, double z) {
  Mat s;
  s.m[0][0] = x;
  s.m[1][1] = y;
  s.m[2][2] = z;
  return s;
}

Mat Mat::rotate(double degrees, double x, double y, double z) {
  double len = std::sqrt(x * x + y * y + z * z);
  x /= len;
  y /= len;
  z /= len;
  double s = std::sin(degrees * kDegToRad), c = std::cos(degrees * kDegToRad);
  Mat r;
  r.m[0][0] = x * x + (1 - x * x) * c;
  r.m[0][1] = x * y * (1 - c) - z * s;
  r.m[0][2] = x * z * (1 - c) + y * s;
  r.m[1][0] = x * y * (1 - c) + z * s;
  r.m[1][1] = y * y + (1 - y * y) * c;
  r.m[1][2] = y * z * (1 - c) - x * s;
  r.m[2][0] = x * z * (1 - c) - y * s;
  r.m[2][1] = y * z * (1 - c) + x * s;
  r.m[2][2] = z * z + (1 - z * z) * c;
  return r;
}

namespace {

struct V3 {
  double x, y, z;
};
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 crossd(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double lend(V3 a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }
V3 normd(V3 a) {
  double l = lend(a);
  return {a.x / l, a.y / l, a.z / l};
}

}  // namespace

std::optional<Mat> lookAt(Vec3f eyeF, Vec3f lookF, Vec3f upF) {
  V3 eye{eyeF.x, eyeF.y, eyeF.z}, look{lookF.x, lookF.y, lookF.z}, up{upF.x, upF.y, upF.z};
  V3 d = sub(look, eye);
  if (lend(d) == 0 || lend(up) == 0) return std::nullopt;
  V3 dir = normd(d);
  V3 c = crossd(normd(up), dir);
  if (lend(c) < 1e-9) return std::nullopt;
  V3 right = normd(c);
  V3 newUp = crossd(dir, right);
  Mat camToWorld;
  V3 cols[4] = {right, newUp, dir, eye};
  for (int j = 0; j < 4; ++j) {
    camToWorld.m[0][j] = cols[j].x;
    camToWorld.m[1][j] = cols[j].y;
    camToWorld.m[2][j] = cols[j].z;
  }
  return camToWorld.inverse();
}

Quaternion quaternionFromMatrix(const double r[3][3]) {
  // Shepperd's method: pick the largest diagonal term for stability.
  double tr = r[0][0] + r[1][1] + r[2][2];
  double w, x, y, z;
  if (tr > 0) {
    double s = std::sqrt(tr + 1.0) * 2;
    w = 0.25 * s;
    x = (r[2][1] - r[1][2]) / s;
    y = (r[0][2] - r[2][0]) / s;
    z = (r[1][0] - r[0][1]) / s;
  } else if (r[0][0] > r[1][1] && r[0][0] > r[2][2]) {
    double s = std::sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2;
    w = (r[2][1] - r[1][2]) / s;
    x = 0.25 * s;
    y = (r[0][1] + r[1][0]) / s;
    z = (r[0][2] + r[2][0]) / s;
  } else if (r[1][1] > r[2][2]) {
    double s = std::sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2;
    w = (r[0][2] - r[2][0]) / s;
    x = (r[0][1] + r[1][0]) / s;
    y = 0.25 * s;
    z = (r[1][2] + r[2][1]) / s;
  } else {
    double s = std::sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2;
    w = (r[1][0] - r[0][1]) / s;
    x = (r[0][2] + r[2][0]) / s;
    y = (r[1][2] + r[2][1]) / s;
    z = 0.25 * s;
  }
  double n = std::sqrt(w * w + x * x + y * y + z * z);
  return {float(w / n), float(x / n), float(y / n), float(z / n)};
}

std::optional<Pose> decompose(const Mat& m) {
  double r[3][3];
  double s[3];
  for (int j = 0; j < 3; ++j) {
    s[j] = std::sqrt(m.m[0][j] * m.m[0][j] + m.m[1][j] * m.m[1][j] + m.m[2][j] * m.m[2][j]);
    if (!(s[j] > 1e-30) || !std::isfinite(s[j])) return std::nullopt;
    for (int i = 0; i < 3; ++i) r[i][j] = m.m[i][j] / s[j];
  }
  // Columns must be orthogonal: otherwise the matrix has shear (e.g. a
  // non-uniform scale applied after a rotation), which T*R*S cannot express.
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      double d = r[0][a] * r[0][b] + r[1][a] * r[1][b] + r[2][a] * r[2][b];
      if (std::fabs(d) > 1e-5) return std::nullopt;
    }
  double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
               r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
  if (det < 0) {  // a reflection: carry it in the scale, keep R proper
    s[0] = -s[0];
    for (int i = 0; i < 3; ++i) r[i][0] = -r[i][0];
  }
  Pose p;
  p.translate = {float(m.m[0][3]), float(m.m[1][3]), float(m.m[2][3])};
  p.rotate = quaternionFromMatrix(r);
  p.scale = {float(s[0]), float(s[1]), float(s[2])};
  return p;
}

std::string scaleProblem(const Mat& m) {
  namespace L = scene::limits;
  for (int j = 0; j < 3; ++j) {
    double s = std::sqrt(m.m[0][j] * m.m[0][j] + m.m[1][j] * m.m[1][j] + m.m[2][j] * m.m[2][j]);
    if (s >= double(L::kMinScale) && s <= double(L::kMaxScale)) continue;
    std::ostringstream o;
    o << "it scales an axis by " << s << ", which is " << (s < double(L::kMinScale) ? "degenerate (too small)" : "too large")
      << "; tdpm needs scale factors in [" << L::kMinScale << ", " << L::kMaxScale << "]";
    return o.str();
  }
  return "";
}

Mat mirrorX() { return Mat::scale(-1, 1, 1); }

Pose mirrorPose(const Pose& p) {
  Pose q = p;
  q.translate.x = -q.translate.x;
  // W R W for W = diag(-1, 1, 1): the rotation about the mirrored axis by
  // the opposite angle, i.e. (w, x, -y, -z).
  q.rotate = {p.rotate.w, p.rotate.x, -p.rotate.y, -p.rotate.z};
  q.scale.x = -q.scale.x;
  return q;
}

}  // namespace tdpm::pbrt
