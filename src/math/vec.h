// math/vec.h — small value types: Vec2f, Vec3f (points, directions, normals)
// and Rgb (radiometric quantities per channel). Plain structs, inline ops.
#pragma once
#include <algorithm>
#include <cmath>

namespace tdpm {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;

struct Vec2f {
  float x = 0, y = 0;
  constexpr Vec2f() = default;
  constexpr Vec2f(float x_, float y_) : x(x_), y(y_) {}
};

struct Vec3f {
  float x = 0, y = 0, z = 0;
  constexpr Vec3f() = default;
  constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}
  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

inline Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3f operator-(Vec3f a) { return {-a.x, -a.y, -a.z}; }
inline Vec3f operator*(Vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3f operator*(float s, Vec3f a) { return a * s; }
inline Vec3f operator*(Vec3f a, Vec3f b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline Vec3f operator/(Vec3f a, float s) { return a * (1.0f / s); }
inline Vec3f& operator+=(Vec3f& a, Vec3f b) { return a = a + b; }
inline Vec3f& operator-=(Vec3f& a, Vec3f b) { return a = a - b; }
inline Vec3f& operator*=(Vec3f& a, float s) { return a = a * s; }

inline float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3f cross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float lengthSquared(Vec3f a) { return dot(a, a); }
inline float length(Vec3f a) { return std::sqrt(dot(a, a)); }
inline Vec3f normalize(Vec3f a) { return a / length(a); }
inline Vec3f lerp(Vec3f a, Vec3f b, float t) { return a * (1.0f - t) + b * t; }
inline Vec3f vmin(Vec3f a, Vec3f b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3f vmax(Vec3f a, Vec3f b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool isFinite(Vec3f a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }
// Faces n toward v (flip if they point into opposite half-spaces).
inline Vec3f faceForward(Vec3f n, Vec3f v) { return dot(n, v) < 0.0f ? -n : n; }

struct Rgb {
  float r = 0, g = 0, b = 0;
  constexpr Rgb() = default;
  constexpr Rgb(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
  constexpr explicit Rgb(float s) : r(s), g(s), b(s) {}
  float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
  bool isBlack() const { return r == 0.0f && g == 0.0f && b == 0.0f; }
  float maxComponent() const { return std::max(r, std::max(g, b)); }
  float average() const { return (r + g + b) * (1.0f / 3.0f); }
  // Rec. 709 luminance.
  float luminance() const { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
};

inline Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
inline Rgb operator-(Rgb a, Rgb b) { return {a.r - b.r, a.g - b.g, a.b - b.b}; }
inline Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
inline Rgb operator*(Rgb a, float s) { return {a.r * s, a.g * s, a.b * s}; }
inline Rgb operator*(float s, Rgb a) { return a * s; }
inline Rgb operator/(Rgb a, float s) { return a * (1.0f / s); }
inline Rgb& operator+=(Rgb& a, Rgb b) { return a = a + b; }
inline Rgb& operator*=(Rgb& a, Rgb b) { return a = a * b; }
inline Rgb& operator*=(Rgb& a, float s) { return a = a * s; }
inline bool isFinite(Rgb a) { return std::isfinite(a.r) && std::isfinite(a.g) && std::isfinite(a.b); }

}  // namespace tdpm
