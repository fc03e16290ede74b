// The MIS weights of the reuse connections (docs/design.md section 5), shared by the connect
// kernel and the host's unit tests, which check that the strategies' weights add to 1.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// The three strategies that find a connected path x - Y - Z - w - ..., x the eye vertex and w the
// light path's vertex before Z: the light tracer stepped to Z and Y, and x connects to Y (L); x's
// BSDF sample found Y, the light tracer stepped to Z, and Y connects to Z (E); x's BSDF sample
// found Y, Y's found Z, and Z connects to w (E2). Each samples the two edges a connection's
// geometry term does not cancel in turn: E2 is the one left where x, Y and Z are all close (a
// corner), where L and E both carry a 1/d^2.
#define PR_STRATEGY_L 0u
#define PR_STRATEGY_E 1u
#define PR_STRATEGY_E2 2u

// The pdf per unit area at a point at squared distance dist2 whose normal makes |cosine| cos_t
// with the direction sampled with solid-angle pdf pdf_w.
PR_INLINE float solid_angle_to_area_pdf(float pdf_w, float cos_t, float dist2) {
  return pdf_w * cos_t / dist2;
}

// Whether strategy E2 takes part in a path whose edges Y - Z and Z - w have squared lengths yz2
// and zw2: only where Z - w is the longer by sqrt(threshold) at least. Elsewhere Y - Z is not the
// short edge E2 is for, and every view of the path (L's, E's, E2's) can tell from the lengths
// alone, before evaluating a BSDF or rebuilding a vertex, that E2 has no share.
PR_INLINE int strategy_e2_takes_part(float yz2, float zw2, float threshold) {
  return threshold > 0.0f && zw2 >= threshold * yz2;
}

// The weight of `strategy` for a path whose area pdfs are, of Y: p_l under the light tracer (from
// Z) and p_e under x's BSDF sample; of Z: q_l under the light tracer (from w) and q_e under Y's
// BSDF sample. The strategies' path pdfs are then p_l q_l (L), p_e q_l (E) and p_e q_e (E2). E
// takes part where r1 = p_e / p_l >= threshold, E2 where r2 = q_e / q_l >= threshold and
// r1 r2 >= threshold; among those taking part, the power heuristic; L alone otherwise, so that
// E and E2 cost shadow rays only near the 1/d^2 singularities where L's variance is unbounded.
// A strategy that cannot make the path has pdf 0 (E: p_e = 0; E2: q_e = 0 too, as where Z is
// the light's vertex or a delta surface, or strategy_e2_takes_part is false), and a ratio 0 / 0
// (NaN) leaves a strategy out. Where L cannot (p_l = 0 < p_e), r1 = inf and E or E2 takes the path.
// threshold 0 leaves L alone. The weights add to 1 always.
PR_INLINE float connection_mis_weight(u32 strategy, float p_l, float p_e, float q_l, float q_e,
                                      float threshold) {
  const float r1 = p_e / p_l, r2 = q_e / q_l, r12 = r1 * r2;
  const int on_e = threshold > 0.0f && r1 >= threshold;
  const int on_e2 = threshold > 0.0f && r2 >= threshold && r12 >= threshold;
  // Each weight as 1 / (sum of the others' pdfs over its own), finite where a ratio is inf.
  if (strategy == PR_STRATEGY_L)
    return 1.0f / (1.0f + (on_e ? r1 * r1 : 0.0f) + (on_e2 ? r12 * r12 : 0.0f));
  if (strategy == PR_STRATEGY_E)
    return on_e ? 1.0f / (1.0f / (r1 * r1) + 1.0f + (on_e2 ? r2 * r2 : 0.0f)) : 0.0f;
  return on_e2 ? 1.0f / (1.0f / (r12 * r12) + (on_e ? 1.0f / (r2 * r2) : 0.0f) + 1.0f) : 0.0f;
}

PR_NAMESPACE_END
