// sampling/sampler.cpp — sampler kind names.
#include "sampling/sampler.h"

namespace tdpm {

const char* samplerName(SamplerKind k) { return k == SamplerKind::Random ? "random" : "sobol"; }

bool parseSamplerKind(const std::string& name, SamplerKind& out) {
  if (name == "random") out = SamplerKind::Random;
  else if (name == "sobol") out = SamplerKind::Sobol;
  else return false;
  return true;
}

}  // namespace tdpm
