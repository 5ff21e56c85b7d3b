// photon/knn_heap.h — the bounded max-heap of the k nearest candidates,
// shared by the photon kd-tree's k-NN (photon/kdtree.cpp) and the path
// tracer's caustic-guide k-NN over its compact nodes (render/caustic_guide.cpp).
// Root = the farthest candidate, so the search radius is d2[0] once k are held.
#pragma once
#include <cstdint>
#include <limits>

namespace tdpm::photon {

// The choice between the two children is branch-free: it is a coin flip for
// the branch predictor, and sifting is a large part of the k-NN's time.
// (A 4-ary heap measured slower here.) d2[n] must hold -infinity (a
// sentinel right child for the last left child, never chosen): arrays hold
// k + 1 entries.
inline void knnSiftDown(float* d2, uint32_t* idx, int n, int i) {
  float d = d2[i];
  uint32_t v = idx[i];
  for (;;) {
    int c = 2 * i + 1;
    if (c >= n) break;
    c += int(d2[c + 1] > d2[c]);
    float dc = d2[c];
    if (dc <= d) break;
    d2[i] = dc;
    idx[i] = idx[c];
    i = c;
  }
  d2[i] = d;
  idx[i] = v;
}

// Offers candidate q at squared distance dist (already known < r2): fills
// the first k slots, heapifies when full, then replaces the farthest. r2
// becomes the farthest held distance once k are held.
inline void knnOffer(float* d2, uint32_t* idx, int k, int& count, float& r2, uint32_t q, float dist) {
  if (count < k) {
    idx[count] = q;
    d2[count] = dist;
    if (++count == k) {
      d2[k] = -std::numeric_limits<float>::infinity();
      for (int i = k / 2 - 1; i >= 0; --i) knnSiftDown(d2, idx, k, i);
      r2 = d2[0];
    }
  } else {
    d2[0] = dist;
    idx[0] = q;
    knnSiftDown(d2, idx, k, 0);
    r2 = d2[0];
  }
}

}  // namespace tdpm::photon
