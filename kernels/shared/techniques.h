// The techniques a stage's program is compiled with: -D flags, each 0 or 1, that the integrator
// building it passes (host render/kernel_programs.h, techniqueBuildOptions), as Cycles compiles
// its kernels for KERNEL_FEATURE_* masks. A technique's hooks are called as `if (PR_X && ...)`,
// so a program built without it carries none of its code, and its buffers stay one unread
// element. Small stages (pt_generate, pt_shadow, light_trace) take the same switches at run time
// instead: compiled both ways they would double the programs for little code.
#pragma once

// Eye paths weighted against the connections to stored light paths (--eye-paths in reuse and
// retrace; C = paths_per_pixel > 0): pt_shade's MIS share of each path ending on a light
// (pathtrace/shade_eye_paths.h), connect's terms deferred to connect_shadow (reuse/connect.cl).
#ifndef PR_EYE_PATHS
#define PR_EYE_PATHS 0
#endif

// Path and direct-light resampling (--resample): pt_shade tracks each eye path from x_1 and
// offers what reaches a light to the pixel's reservoirs (pathtrace/shade_resample.h).
#ifndef PR_RESAMPLE
#define PR_RESAMPLE 0
#endif
