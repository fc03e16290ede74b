// Internal invariants, as pbrt's CHECK and DCHECK. A failed check is a bug in pathreuse, not
// bad input: it throws RuntimeError naming the condition and the place (exit code 1).
// PR_CHECK is always compiled; PR_DCHECK (costlier: whole-structure walks) only where
// PATHREUSE_DCHECKS is defined, which the sanitizer build of CI and Debug builds do.
#pragma once

namespace pr {

[[noreturn]] void checkFailed(const char* condition, const char* file, int line);

}  // namespace pr

#define PR_CHECK(cond) ((cond) ? (void)0 : ::pr::checkFailed(#cond, __FILE__, __LINE__))

#ifdef PATHREUSE_DCHECKS
#define PR_DCHECK(cond) PR_CHECK(cond)
#else
#define PR_DCHECK(cond) ((void)0)
#endif
