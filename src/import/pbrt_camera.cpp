// import/pbrt_camera.cpp — the thin lens of pbrt's perspective camera:
// "lensradius" and "focaldistance" (pbrt-v3 and pbrt-v4 both read these
// names; their default focal distance is 1e6), plus "focusdistance", the
// realistic camera's name for the same length, which scenes also put on a
// perspective camera. Camera-space lengths: the importer scales them by the
// camera transform's scale (pbrt_import.cpp). docs/pbrt-import.md.
#include <cmath>

#include "import/pbrt_importer.h"
#include "scene/limits.h"

namespace tdpm::pbrt::detail {

void Importer::readThinLens(const ParamSet& ps) {
  lensRadius_ = ps.getFloat("lensradius", 0);
  if (ps.has("lensradius") && !(lensRadius_ >= 0 && lensRadius_ <= scene::limits::kMaxCoordinate))
    ps.fail(*ps.find("lensradius"), "lensradius must be in [0, " + fmtNum(scene::limits::kMaxCoordinate) +
                                        "] (0: a pinhole camera), got " + fmtNum(lensRadius_));
  const char* name = "focaldistance";
  if (ps.has("focusdistance")) {
    if (ps.has("focaldistance"))
      ps.fail(*ps.find("focusdistance"), "both focaldistance and focusdistance are given; give one");
    name = "focusdistance";
  }
  focalDistance_ = ps.getFloat(name, 1e6);
  if (ps.has(name) && !(focalDistance_ > 0 && focalDistance_ <= scene::limits::kMaxCoordinate))
    ps.fail(*ps.find(name), std::string(name) + " must be in (0, " + fmtNum(scene::limits::kMaxCoordinate) + "], got " +
                                fmtNum(focalDistance_));
}

}  // namespace tdpm::pbrt::detail
