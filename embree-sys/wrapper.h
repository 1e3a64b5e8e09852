/* Embree 3's header-defined helpers (rtcInitIntersectContext, rtcInitPointQueryContext, ...)
 * are declared `inline`, which in C gives them no linkable symbol. Declaring them `static inline`
 * here lets bindgen's wrap_static_fns emit one exported C wrapper per helper, which build.rs
 * compiles with cc. A macro is never re-expanded inside its own body, so this is well-defined. */
#define inline static inline
#include <embree3/rtcore.h>
#undef inline
