// photon/surface_tag.h — the 6-bit "surface tag" a photon keeps in the
// store's free flag bits (store.h: userFlags), and the rule the estimates
// use it for: a photon that arrived on the other side of the same object's
// surface as the gather point is never part of the gather point's estimate.
//
// Why: the side test dot(n, w_i) > 0 alone lets light through the convex
// edges and thin parts of closed objects. At a point x outside a box, near
// an edge, the k nearest photons include photons stored on the *inside* of
// the adjacent face; they arrived from inside the box, but from a point
// nearer to x's face than they are, so their w_i has dot(n, w_i) > 0 and
// they passed (issue 11, item 4: a point light inside a closed box lit its
// outside, mean 0.027, max 3.96, where the path tracer gives exactly 0). The
// same happens through a box thinner than the search radius (the photons on
// the inside of the far face face the same way as x's face). Neither the
// photon's position nor its direction can tell such a photon from one on the
// outside of the adjacent face; which side of which surface it lies on can.
//
// Layout: bit 0 = the photon arrived on the back side of the surface's
// outward geometric normal (dot(n_geometric, w_i) < 0); bits 1-5 = an
// object code 1..31 (object index mod 31, plus 1); code 0 = untagged (a
// photon or a query without a surface: never rejected by this rule). Two
// different objects whose codes collide are treated as one: a photon of one
// on the back side of its normal is then dropped at a front-side point of the
// other (or vice versa), which at worst darkens a band of one search radius
// along where they meet; it cannot add light.
#pragma once
#include <cstdint>

namespace tdpm::photon {

constexpr uint8_t kNoSurfaceTag = 0;
constexpr uint32_t kSurfaceCodes = 31;

// The tag of a photon stored on (or a gather point seen from) `backSide`
// of object `objectIndex`.
constexpr uint8_t surfaceTag(uint32_t objectIndex, bool backSide) {
  return uint8_t(((objectIndex % kSurfaceCodes + 1) << 1) | (backSide ? 1u : 0u));
}

// Whether a photon tagged `photon` lies on the other side of the same
// object's surface as a gather point tagged `query`: same code, the other
// side bit. Untagged queries (code 0) accept everything.
constexpr bool otherSideOfSameSurface(uint8_t photon, uint8_t query) {
  return (photon ^ query) == 1u && (query >> 1) != 0u;
}

}  // namespace tdpm::photon
