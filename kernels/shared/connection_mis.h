// The MIS weights of the reuse connections (docs/design.md section 5), shared by the connect
// kernel and the host's unit tests, which check that the strategies' weights add to 1.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// The two strategies that find a connected path x - Y - y_{k-1} - ...: the light tracer stepped
// to Y and x connects to it (L), or x's BSDF sample found Y and Y connects to y_{k-1} (E).
#define PR_STRATEGY_L 0u
#define PR_STRATEGY_E 1u

// The pdf per unit area at a point at squared distance dist2 whose normal makes |cosine| cos_t
// with the direction sampled with solid-angle pdf pdf_w.
PR_INLINE float solid_angle_to_area_pdf(float pdf_w, float cos_t, float dist2) {
  return pdf_w * cos_t / dist2;
}

// The weight of `strategy` for a path whose area pdfs of Y are p_l under L and p_e under E:
// the power heuristic on r = p_e / p_l where r >= threshold, and L alone below it, so that E
// costs shadow rays only near the 1/d^2 singularity where L's variance is unbounded. E cannot
// make the path: pass p_e = 0 (r = 0, or NaN where p_l = 0 too: L alone either way). L cannot
// (p_l = 0 < p_e): r = inf, E alone. threshold 0 turns E off. The weights add to 1 always.
PR_INLINE float connection_mis_weight(u32 strategy, float p_l, float p_e, float threshold) {
  const float r = p_e / p_l;
  const float w_l = (threshold > 0.0f && r >= threshold) ? 1.0f / (1.0f + r * r) : 1.0f;
  return strategy == PR_STRATEGY_L ? w_l : 1.0f - w_l;
}

// --eye-paths (docs/design.md section 5, "Eye paths"): the weight of one of the three strategies
// that can make a path ending on a light, L (the first eye vertex joined to a stored light
// vertex), N (the eye path's next-event estimation) and H (its BSDF sample meets the emitter),
// given r1 and r2, the other two strategies' densities of the path over this one's: the power
// heuristic 1 / (1 + r1^2 + r2^2). A NaN ratio (0 / 0: neither makes the path) counts as 0, an
// infinite one gives 0. Computed from the same three densities, the weights add to 1.
PR_INLINE float eye_path_share(float r1, float r2) {
  const float a = r1 == r1 ? r1 * r1 : 0.0f;
  const float b = r2 == r2 ? r2 * r2 : 0.0f;
  return 1.0f / (1.0f + a + b);
}

PR_NAMESPACE_END
