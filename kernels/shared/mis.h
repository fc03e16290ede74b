// Every MIS and resampling weight of the renderer (docs/design.md sections 5 and 6), shared by
// the kernels and the host's unit tests (tests/mis_test.cpp):
//   densities    solid_angle_to_area_pdf, area_pdf_g, and the PathVertex record: a vertex's
//                forward and reverse densities per unit area and its delta flag;
//   running      MisChain (two products) and mis_ratio_* (one ratio): a sub-path's densities
//                gathered vertex by vertex, as light_trace's EyePathWalk and pt_shade's
//                eye_ratio keep them;
//   weights      power_heuristic (two densities), mis_power_share (density ratios, up to three
//                strategies; mis_power_share_n for any number), mis_connection_weight (L/E with
//                a threshold);
//   resampling   mis_balance (generalized balance over reservoirs), gris_weight,
//                ris_contribution_weight and ris_accept (the reservoirs of connect.cl).
// Each weight keeps the float operations, in their order, that the kernels had before they
// shared it, so that frames stay bit for bit. No expression here multiplies and adds at once:
// OpenCL contracts such expressions into fma by default, and which kernel includes this before
// shared/bvh.h turns that off must not change a weight.
#pragma once

#include "shared/common.h"

PR_NAMESPACE_BEGIN

// --- Densities --------------------------------------------------------------------------------

// The pdf per unit area at a point at squared distance dist2 whose normal makes |cosine| cos_t
// with the direction sampled with solid-angle pdf pdf_w.
PR_INLINE float solid_angle_to_area_pdf(float pdf_w, float cos_t, float dist2) {
  return pdf_w * cos_t / dist2;
}

// The same with g = |cos| / dist2 of the segment taken once, where both of its directions'
// densities use it (EyePathWalk).
PR_INLINE float area_pdf_g(float pdf_w, float g) {
  return pdf_w * g;
}

// A vertex of a path as MIS sees it (Veach 1997 ch. 10; pbrt-v4's BDPT keeps the same pair per
// vertex): pdf_fwd, the density per unit area with which its own sub-path sampled it from the
// vertex before; pdf_rev, the density with which the other side, walking the path the other
// way, samples it from the vertex after; delta, whether it scatters by a delta lobe. A density
// sampled from a delta vertex counts as 1 on both sides (mis_sampled): the strategies that
// differ there make the path alike. Kept in this form by none of today's kernels, which gather
// the same products as they trace (MisChain, mis_ratio_*); it is the reference that those are
// tested against, and the form a strategy that stores its vertices would keep.
typedef struct {
  float pdf_fwd, pdf_rev;
  int delta;
} PathVertex;

// A density sampled from a vertex that was delta or not: 1 from a delta vertex.
PR_INLINE float mis_sampled(float pdf, int from_delta) {
  return from_delta ? 1.0f : pdf;
}

// --- Running products along a sub-path ---------------------------------------------------------

// A sub-path's densities gathered as it is traced, SmallVCM's running dVC kept as its two
// factors: fwd, the product of its vertices' pdf_fwd; rev, that of their pdf_rev. Two products
// where factors that only a later kernel knows join the ratio (the light side of --eye-paths).
typedef struct {
  float fwd, rev;
} MisChain;

PR_INLINE MisChain mis_chain_start(void) {
  MisChain c;
  c.fwd = c.rev = 1.0f;
  return c;
}

// Arriving at a vertex with density pdf_fwd, from a vertex that was delta or not.
PR_INLINE void mis_chain_arrive(MisChain* c, float pdf_fwd, int from_delta) {
  c->fwd *= mis_sampled(pdf_fwd, from_delta);
}

// Leaving a vertex (delta or not): the other side's density pdf_rev of the vertex before.
PR_INLINE void mis_chain_leave(MisChain* c, float pdf_rev, int delta) {
  c->rev *= mis_sampled(pdf_rev, delta);
}

// The same gathered as one ratio, the other side's densities over this side's (the eye side of
// --eye-paths, one float in PathState): divided by each pdf_fwd on arriving, multiplied by each
// pdf_rev on leaving.
PR_INLINE float mis_ratio_arrive(float ratio, float pdf_fwd, int from_delta) {
  return ratio / mis_sampled(pdf_fwd, from_delta);
}
PR_INLINE float mis_ratio_leave(float ratio, float pdf_rev, int delta) {
  return ratio * mis_sampled(pdf_rev, delta);
}

// The products of stored records v[first..last] (inclusive), as MisChain gathers them vertex
// by vertex: each pdf_fwd counted from v[i - 1] (v[first - 1] taken as non-delta), each pdf_rev
// of v[i - 1] counted from v[i], i = first + 1 .. last.
PR_INLINE MisChain mis_chain_of(const PathVertex* v, u32 first, u32 last) {
  MisChain c = mis_chain_start();
  for (u32 i = first; i <= last; ++i) {
    mis_chain_arrive(&c, v[i].pdf_fwd, i > first ? v[i - 1u].delta : 0);
    if (i > first) mis_chain_leave(&c, v[i - 1u].pdf_rev, v[i].delta);
  }
  return c;
}

// --- Weights --------------------------------------------------------------------------------

// The power heuristic with beta = 2 (Veach 1997, eq. 9.13) from the two strategies' densities,
// one sample each: this strategy's (pdf_a) and the other's. 0 where neither makes the path.
// The path tracer's light and BSDF sampling (next_event, pt_shade, connect's emitter hits).
PR_INLINE float power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

// The power heuristic's term of one other strategy, r = its density over this one's: r^2. A
// NaN ratio (0 / 0: neither makes the path) counts as 0, an infinite one gives this strategy 0.
PR_INLINE float mis_power_term(float r) {
  return r == r ? r * r : 0.0f;
}

// The power heuristic from density ratios, r_i = strategy i's density of the path over this
// one's: 1 / (1 + sum r_i^2) (Veach 1997 ch. 10 computes BDPT's weights from such ratios).
// Up to three strategies; pass 0 for a strategy that cannot make the path. Computed from the
// same densities, every strategy's weight of a path adds to 1.
PR_INLINE float mis_power_share(float r1, float r2) {
  return 1.0f / (1.0f + mis_power_term(r1) + mis_power_term(r2));
}

// The same over n other strategies.
PR_INLINE float mis_power_share_n(const float* r, u32 n) {
  float sum = 1.0f;
  for (u32 i = 0u; i < n; ++i) sum += mis_power_term(r[i]);
  return 1.0f / sum;
}

// The two strategies that find a connected path x - Y - y_{k-1} - ... (--no-eye-paths): the
// light tracer stepped to Y and x connects to it (L), or x's BSDF sample found Y and Y connects
// to y_{k-1} (E).
#define PR_STRATEGY_L 0u
#define PR_STRATEGY_E 1u

// The weight of `strategy` for a path whose area pdfs of Y are p_l under L and p_e under E:
// the power heuristic on r = p_e / p_l where r >= threshold, and L alone below it, so that E
// costs shadow rays only near the 1/d^2 singularity where L's variance is unbounded. E cannot
// make the path: pass p_e = 0 (r = 0, or NaN where p_l = 0 too: L alone either way). L cannot
// (p_l = 0 < p_e): r = inf, E alone. threshold 0 turns E off. The weights add to 1 always.
PR_INLINE float mis_connection_weight(u32 strategy, float p_l, float p_e, float threshold) {
  const float r = p_e / p_l;
  const float w_l = (threshold > 0.0f && r >= threshold) ? mis_power_share(r, 0.0f) : 1.0f;
  return strategy == PR_STRATEGY_L ? w_l : 1.0f - w_l;
}

// --- Resampling -------------------------------------------------------------------------------

// The generalized balance heuristic over reservoirs (Lin et al. 2022, GRIS): reservoir a's
// weight at a sample y, m_a(y) = c_a p_a(y) / sum_j c_j p_j(y), with c_j the reservoirs'
// confidences and p_j their targets at y; here for two (a and b). 0 where no target is
// positive at y. The weights of all reservoirs at y add to 1.
PR_INLINE float mis_balance(float c_a, float p_a, float c_b, float p_b) {
  const float a = c_a * p_a;
  const float b = c_b * p_b;
  const float den = a + b;
  return den > 0.0f ? a / den : 0.0f;
}

// The same over n reservoirs, reservoir i's weight.
PR_INLINE float mis_balance_n(const float* c, const float* p, u32 i, u32 n) {
  float den = 0.0f;
  for (u32 j = 0u; j < n; ++j) {
    const float cp = c[j] * p[j];
    den += cp;
  }
  const float a = c[i] * p[i];
  return den > 0.0f ? a / den : 0.0f;
}

// A reservoir's resampling weight in GRIS, m_i(y_i) p(y_i) W_i: its MIS weight m, the target
// p at its sample and its unbiased contribution weight W. 0 where m is (a reservoir no target
// can have made counts nothing, whatever its W).
PR_INLINE float gris_weight(float m, float p, float w) {
  return m > 0.0f ? m * p * w : 0.0f;
}

// The unbiased contribution weight of a sample y resampled from candidates whose resampling
// weights sum to w_sum, with target p(y), one of n kept (Talbot 2005): w_sum / (p(y) n).
PR_INLINE float ris_contribution_weight(float w_sum, float p, float n) {
  return w_sum / (p * n);
}

// Streaming weighted reservoir sampling: with u uniform in [0, 1), whether a candidate of
// weight w replaces the kept one, w_sum now including w (probability w / w_sum; the first
// candidate is always kept).
PR_INLINE int ris_accept(float u, float w_sum, float w) {
  return u * w_sum < w;
}

// --- Path resampling across pixels (kernels/pathtrace/resample.cl) -----------------------------

// Pairwise MIS (Bitterli 2022) over a canonical reservoir c and k neighbours, each compared with
// the canonical one alone: O(k) where the balance heuristic is O(k^2). p_i is neighbour i's
// target pulled back to the sample (p_i(T(y)) |J|), p_c the canonical target at it, c_* the
// confidences (how many samples' domains a reservoir stands for) and C = c_c + sum_i c_i. A
// neighbour's sample gets
//   m_i(y) = c_i / C * c_i p_i / (c_i p_i + c_c p_c / k),
// and the canonical sample c_c / C + sum_i c_i / C * (c_c p_c / k) / (c_i p_i + c_c p_c / k):
// for every y the k + 1 weights add to 1, and a domain's share grows with its confidence. With
// every confidence 1 the shares are 1 / (k + 1). A pair where both targets are 0 counts wholly
// to the canonical side.
PR_INLINE float mis_pairwise_neighbor(float c_i, float p_i, float c_c, float p_c, float k,
                                      float total) {
  const float a = c_i * p_i;
  const float b = c_c * p_c / k;
  const float den = a + b;
  return den > 0.0f ? c_i / total * (a / den) : 0.0f;
}

// The canonical side's share of one pair, c_i / C (c_c p_c / k) / (c_i p_i + c_c p_c / k); the
// canonical weight is c_c / C plus the sum of these over the k pairs (mis_pairwise_canonical).
PR_INLINE float mis_pairwise_canonical_term(float c_i, float p_i, float c_c, float p_c, float k,
                                            float total) {
  const float a = c_i * p_i;
  const float b = c_c * p_c / k;
  const float den = a + b;
  return c_i / total * (den > 0.0f ? b / den : 1.0f);
}

PR_INLINE float mis_pairwise_canonical(float term_sum, float c_c, float total) {
  return c_c / total + term_sum;
}

// The Jacobian of the reconnection shift (ReSTIR GI; Lin et al. 2022): a path whose vertex x_2
// is kept while x_1 moves, in solid angle at x_1. g = |cos at x_2| / d^2 of the segment x_1 x_2,
// before (g_src) and after (g_dst): |J| = g_dst / g_src. 0 where the source's is not positive.
PR_INLINE float reconnection_jacobian(float g_dst, float g_src) {
  return g_src > 0.0f ? g_dst / g_src : 0.0f;
}

PR_NAMESPACE_END
