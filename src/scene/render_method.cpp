// scene/render_method.cpp — the table of rendering methods
// (scene/render_method.h): the one place a method's name is spelled.
#include "scene/render_method.h"

namespace tdpm {

namespace {

using K = KernelShrink;
// clang-format off
constexpr RenderMethodTraits kTable[kRenderMethodCount] = {
  //  method                      name            maps   spread  timeDep frames progr. anim.  shrink
    {RenderMethod::PathTrace,    "pathtrace",    false, false,  false,  false, false, true,  K::Spatial},
    {RenderMethod::Static,       "static",       true,  false,  false,  false, false, false, K::Spatial},
    {RenderMethod::Accumulation, "accumulation", true,  false,  false,  true,  true,  false, K::Spatial},
    {RenderMethod::Standard,     "standard",     true,  true,   false,  false, true,  true,  K::Spatial},
    {RenderMethod::Time,         "time",         true,  true,   true,   false, true,  true,  K::SpaceTime},
};
// clang-format on

constexpr bool tableInEnumOrder() {
  for (int i = 0; i < kRenderMethodCount; ++i)
    if (int(kTable[i].method) != i) return false;
  return true;
}
static_assert(tableInEnumOrder(), "kTable must list the methods in enum order");

}  // namespace

const RenderMethodTraits& renderMethodTraits(RenderMethod m) { return kTable[int(m)]; }

std::optional<RenderMethod> parseRenderMethod(const std::string& name) {
  for (const RenderMethodTraits& t : kTable)
    if (name == t.name) return t.method;
  return std::nullopt;
}

std::vector<std::string> renderMethodNames() {
  std::vector<std::string> v;
  for (const RenderMethodTraits& t : kTable) v.push_back(t.name);
  return v;
}

std::string renderMethodList(const char* separator) {
  std::string s;
  for (const RenderMethodTraits& t : kTable) s += std::string(s.empty() ? "" : separator) + t.name;
  return s;
}

}  // namespace tdpm
