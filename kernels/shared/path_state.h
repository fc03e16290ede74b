// Per-sample state of the wavefront path tracer, in device buffers. Radiance is kept apart, in
// one float4 per sample, which the accumulate kernel shared by all modes adds to the film.
#pragma once

#include "shared/types.h"

PR_NAMESPACE_BEGIN

// The path tracer's ray counters (its `rays` buffer) and their --stats names.
#define PR_PT_COUNTERS(X) \
  X(CAMERA, "camera")     \
  X(BOUNCE, "bounce")     \
  X(SHADOW, "shadow")     \
  X(RECONNECT, "reconnect")
#define PR_PT_ENUM(name, key) PR_PT_##name,
enum { PR_PT_COUNTERS(PR_PT_ENUM) PR_PT_COUNT };
#undef PR_PT_ENUM
enum { PR_PT_ROW = PR_COUNTER_ROW(PR_PT_COUNT) };  // one lane of the `rays` buffer

// The sizes of the queues pt_shade appends to (its queue_sizes buffer).
enum { PR_QUEUE_LIVE, PR_QUEUE_SHADOW, PR_QUEUE_COUNT };

// 112 bytes.
typedef struct {
  Ray ray;
  float tp_r, tp_g, tp_b;
  float last_pdf;  // solid-angle pdf of the BSDF sample that made `ray`; 0 after delta/camera
  u32 depth;       // surface interactions so far
  u32 pixel;
  u32 alive;                        // 0: ended at the last bounce (in no queue since)
  u32 rng_dim;                      // next random dimension of this sample
  u32 flags;                        // PR_PATH_*
  float prev_x, prev_y, prev_z;     // the vertex `ray` leaves and its shading normal (for the
  float prev_nx, prev_ny, prev_nz;  // emitter pdf of its hit)
  // --eye-paths (shared/eye_paths.h), on the vertices x_2.. after the first non-delta one:
  u32 x1_depth;     // depth of the first non-delta vertex x_1; 0: not met yet
  float eye_ratio;  // prod of light-tracing densities of x_2..x_{t-1} / eye densities of x_2..x_t
  float seg_cos;    // |cos| of `ray` with the geometric normal of the vertex it leaves
  u32 eye_flags;    // PR_EYE_*
  // Strategy T (--light-tracing, shared/eye_paths.h): until x_1, cos^3 of the camera ray's angle
  // with the camera's axis; at x_1 its camera factor (eye_paths_camera_factor); from x_2 on the
  // path's density under T over that under L (0: T cannot make the path).
  float lt;
} PathState;

#define PR_PATH_SPECULAR 1u  // the last bounce was delta (or the ray is the camera ray)
#define PR_EYE_JOINABLE 1u   // x_2 is non-delta: stored light paths can make this path's ends
// Under a shutter, a segment from x_2 on meets what moves: L cannot make the path (T still can)
// unless PR_EYE_PREFIX_STILL.
#define PR_EYE_MOVED 2u
// Under a shutter, x_1 is the first hit and the camera's segment to it the same at every time
// (camera_segment_still): L joins it to a light path at that path's time, whatever moves beyond.
#define PR_EYE_PREFIX_STILL 4u

// A shadow ray with the contribution it carries if unoccluded: the path tracer's next-event
// estimation (traced where the path is in the bounce's shadow queue) and connect's terms for
// connect_shadow (shared/reuse.h). 48 bytes.
typedef struct {
  Ray ray;
  float c_r, c_g, c_b;
  u32 op;  // connect's terms: how they sum, PR_REC_* (shared/reuse.h); unused by the path tracer
} ShadowRay;

// --- Path resampling across pixels (--resample; kernels/shared/resample.h) ---------------------

// A pixel sample's resampled path and its reservoir: one of the paths beyond the first
// non-delta vertex x_1 that reach a light after at least one more scattering vertex x_2 (the
// terms of the eye path from next-event estimation at x_2 on and from emitters it hits after
// x_2), kept so that a neighbouring pixel can take it by reconnecting its own x_1 to x_2. The
// path's contribution is f = f_1 f_2 rest w in the measure (solid angle at x_1, at x_2, ...):
// x_1's BSDF and cosine along omega_1 (f_1), x_2's along omega_2 (f_2), what lies beyond x_2
// (`rest`) and its MIS weight w (in `rest` but at t = 2, where it depends on x_1's direction).
// The points after x_2 (its suffix) are kept for temporal reuse, which takes a path into the
// next frame only where nothing that moved comes near them (shared/resample.h). 160 bytes.
#define PR_RS_SUFFIX 6  // suffix points kept; a longer path is not reused in the next frame

typedef struct {
  u32 prim, inst;  // x_2 (prim PR_INVALID_INDEX: no path kept)
  float b1, b2;
  float wx, wy, wz;  // omega_2: the direction the path leaves x_2 along
  float g_src;       // |cos at x_2| / d^2 of x_1 x_2; 0 where the path may not be reconnected
  float rest_r, rest_g, rest_b;
  float pdf_light;      // PR_RS_NEE2 and PR_RS_HIT2: the light's solid-angle pdf of omega_2 at x_2
  float f_r, f_g, f_b;  // f at its own pixel
  u32 kind;             // PR_RS_*
  float p_hat;          // the target at its own pixel: luminance(f)
  float w_sum;          // the reservoir's sum of resampling weights (a candidate's own weight)
  float m;              // its confidence: how many pixel samples' domains it has resampled
  u32 suffix;           // the points in sp (PR_RS_SUFFIX at most) | PR_RS_ESCAPES | PR_RS_LONG
  float sp[3 * PR_RS_SUFFIX];  // x_3, x_4, ... and the light's point, in world space
  // PR_RS_JOINED (--mode reuse): the connections' share of the path rebuilt at another x_1 from
  // these two ratios, free of x_1 (rs_eye_share).
  float rn, rh;
} PathReservoir;

#define PR_RS_COUNT_MASK 0xffu
#define PR_RS_ESCAPES 0x100u  // the last point of sp is a direction: the path ends at infinity
#define PR_RS_LONG 0x200u     // more points than sp holds
// Bit k of these: point k of sp lay on a DSG instance. Known by position alone, such a point is
// tested against the moved instances' boxes; a point of the SSG is on none of them.
#define PR_RS_ON_DSG_SHIFT 16u

// A pixel sample's direct light at x_1 and its reservoir (ReSTIR DI beside the paths' one): a
// point y on a light that x_1 sees, from next-event estimation at x_1 or its BSDF sample's
// emitter hit, MIS-weighted against each other as the path tracer weighs them. y is kept as
// itself (a triangle light's point, the environment's direction, a punctual light), so moving it
// to another x_1 has Jacobian 1: f is in area measure on triangle lights (the geometry term at y
// included), in solid angle for the environment and per light for punctual ones. 48 bytes.
typedef struct {
  u32 light;         // the light (PR_INVALID_INDEX: none kept)
  float b1, b2;      // a triangle light's point: barycentrics on its triangle
  float wx, wy, wz;  // the environment's: the direction towards it
  float f_r, f_g, f_b;
  float p_hat, w_sum, m;  // as PathReservoir's
} DirectReservoir;

// A pixel sample's resampled paths as the next frame's temporal reuse finds them: the
// reservoirs and the x_1 they are paths of (surface and the direction it was seen from).
// 240 bytes.
typedef struct {
  PathReservoir r;
  DirectReservoir d;
  u32 prim, inst;  // x_1 (prim PR_INVALID_INDEX: none)
  float b1, b2;
  float wx, wy, wz;
  u32 stamp;  // the frame that wrote it, counted by its PathTracer (rows move between devices)
} PathHistory;

#define PR_RS_DEEP 0u  // the weight is in `rest` (t >= 3, or a delta light)
#define PR_RS_NEE2 1u  // next-event estimation at x_2: w = power heuristic (light, x_2's BSDF)
#define PR_RS_HIT2 2u  // x_2's BSDF sample met an emitter or escaped: w = (x_2's BSDF, light)
#define PR_RS_KIND_MASK 0xfu
// Flags beside the kind (--mode reuse, where the connections to stored light paths make the
// paths from x_2 on too): the path's f holds the eye path's share of it (PR_RS_JOINED), and x_2
// is its last vertex before the light (PR_RS_LAST2).
#define PR_RS_JOINED 0x10u
#define PR_RS_LAST2 0x20u
// A PR_RS_JOINED path short enough for strategy T (eye_paths_camera_len), which makes it where
// its x_1 is seen straight from the camera.
#define PR_RS_CAMERA 0x40u
// A PR_RS_JOINED path that L cannot make (under a shutter, a segment from x_2 on meets what
// moves and x_1 is not PR_EYE_PREFIX_STILL): its f holds what T leaves of it
// (eye_paths_eye_share_l).
#define PR_RS_NO_L 0x80u

// Where a path's candidates stand as pt_shade follows it (one per pixel). 160 bytes.
typedef struct {
  u32 prim, inst;  // x_2
  float b1, b2;
  float f1_r, f1_g, f1_b;  // f_1 (and the transmittance before x_2)
  u32 x1_ok;               // x_1 is rough and omega_1 leaves it above its surface
  float f2_r, f2_g, f2_b;  // f_2 of the path's own omega_2
  float pdf;               // the path's density from x_1 on (BSDF pdfs, roulette)
  float rest_r, rest_g, rest_b;
  float g_src;  // of the path's own omega_2 (0: not reconnectable)
  float wx, wy, wz;
  u32 suffix;                  // as PathReservoir's: the points met after x_2
  float sp[3 * PR_RS_SUFFIX];  // their positions
  float p2;                    // the eye path's density of x_2 per unit area (from x_1)
  float pdf2;                  // x_2's solid-angle pdf of omega_2
} PathTrack;

// An instance that moved or changed shape since the previous frame, for pt_resample's temporal
// test: its bounds then and now (lo xyz, hi xyz each, a little enlarged), its mesh's BVH roots
// then and now (the same where it moved rigidly; the previous shape's where it deformed) and its
// world-to-object transforms then and now (3 x 4 rows), against which a segment is tested
// exactly. Where no shape of the previous frame is known (the first frame), it is its boxes
// alone. The records are a bounding-box tree in preorder (host/render/moved_tree.h): a `node`
// record stands for no instance, both its boxes bound the records of its subtree, and `skip` is
// the first record after that subtree, where a test that misses the boxes goes on. 160 bytes.
typedef struct {
  float box[12];
  u32 root;         // now (PR_INVALID_INDEX: its boxes alone)
  u32 root_before;  // then
  u32 skip;         // the next record outside this one's subtree (the next one, for an instance)
  u32 node;         // 1: an inner node of the tree; 0: an instance
  float before[12], after[12];
} MovedInstance;

// What the resampling kernels are told. 48 bytes.
// Whether they run at all is pt_shade's PR_RESAMPLE (shared/techniques.h).
typedef struct {
  u32 neighbors;    // k of pairwise MIS (0: the pixel's own paths, resampled)
  float radius;     // in pixels
  float min_alpha;  // GGX alpha below which a vertex is too smooth to reconnect at
  float min_dist2;  // squared distance below which x_1 x_2 is too short to reconnect
  u32 width, height;
  float max_m;      // the confidence a reservoir of the previous frame counts at most
  u32 moved_count;  // records in `moved` (pt_resample): what changed since the previous frame
  // --mode reuse: the samples a resampled eye path counts as in its weights against the
  // connections (ReuseParams.eye_count; 1 without --resample).
  float eye_count;
  // Strategy T: N_L A / (spp C W H) (eye_paths_camera_factor); 0: off.
  float lt_scale;
  u32 prev_known;  // pt_resample's prev_vertices and prev_instances hold the previous frame's
  u32 pad2;
} ResampleParams;

PR_NAMESPACE_END

PR_STATIC_ASSERT(sizeof(pr::dev::PathState) == 112, "PathState layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathState, depth) == 48, "PathState layout");
PR_STATIC_ASSERT(offsetof(pr::dev::PathState, flags) == 64, "PathState layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ShadowRay) == 48, "ShadowRay layout");
PR_STATIC_ASSERT(sizeof(pr::dev::PathReservoir) == 160, "PathReservoir layout");
PR_STATIC_ASSERT(sizeof(pr::dev::PathHistory) == 240, "PathHistory layout");
PR_STATIC_ASSERT(sizeof(pr::dev::DirectReservoir) == 48, "DirectReservoir layout");
PR_STATIC_ASSERT(sizeof(pr::dev::PathTrack) == 160, "PathTrack layout");
PR_STATIC_ASSERT(sizeof(pr::dev::ResampleParams) == 48, "ResampleParams layout");
PR_STATIC_ASSERT(sizeof(pr::dev::MovedInstance) == 160, "MovedInstance layout");
