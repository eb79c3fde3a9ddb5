/* scx_embree.h: a small C shim between scx (Rust) and Embree 3 or 4.
 *
 * Why a shim: Embree's context/argument initialisers are header-inline (not exported), its callbacks index
 * ray packets by hand, and its v3 and v4 query signatures differ. The shim hides all that behind a few
 * functions that take plain arrays, so the Rust side needs no Embree knowledge beyond struct sizes.
 *
 * The build script passes SCX_EMBREE_MAJOR (3 or 4) and the include directory it found, so the shim, the
 * bindings and the linked library all come from the same Embree installation. */

#ifndef SCX_EMBREE_H
#define SCX_EMBREE_H

#include <stddef.h>
#include <stdint.h>

#if defined(SCX_EMBREE_MAJOR) && SCX_EMBREE_MAJOR >= 4
#include <embree4/rtcore.h>
#elif defined(SCX_EMBREE_MAJOR)
#include <embree3/rtcore.h>
#elif defined(__has_include)
#if __has_include(<embree4/rtcore.h>)
#include <embree4/rtcore.h>
#else
#include <embree3/rtcore.h>
#endif
#else
#include <embree3/rtcore.h>
#endif

#if RTC_VERSION_MAJOR >= 4
#define SCX_EMBREE_V4 1
/* The per-query state Embree hands back to the intersect callback. */
#define SCX_RTC_CONTEXT struct RTCRayQueryContext
#else
#define SCX_EMBREE_V4 0
#define SCX_RTC_CONTEXT struct RTCIntersectContext
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes. 0 is success, 1..6 are Embree's own RTCError codes (passed through), the rest are the
 * shim's. Every failing call leaves a message for scx_take_error on the calling thread. */
#define SCX_OK 0
/* The hit buffer could not grow (malloc/realloc failed): hits would have been lost. */
#define SCX_ERR_HIT_BUFFER 100
/* An argument is invalid (null pointer, vertex index out of range, packet width not native, ...). */
#define SCX_ERR_INVALID 101
/* Embree reported a hit for a ray id that is not a line of the batch. */
#define SCX_ERR_RAY_ID 102

/* Ray id of padding lanes in the last packet of a batch: never a line index. */
#define SCX_NO_LINE 0xFFFFFFFFu

/* An Embree device and what it supports. Opaque. */
typedef struct scx_device scx_device;
/* A committed Embree scene with one triangle geometry. Opaque. */
typedef struct scx_scene scx_scene;

/* A line to trace: origin, unit direction, and the far end of the segment [0, t_max]. */
typedef struct scx_line {
  float org[3];
  float dir[3];
  float t_max;
} scx_line;

/* One recorded intersection; the same layout as Rust's `RawHit` (#[repr(C)]). */
typedef struct scx_hit {
  float t;       /* distance along the line */
  uint32_t prim; /* triangle index (Embree's primID) */
  uint32_t line; /* index of the line within the batch */
} scx_hit;

/* A growable array of hits, owned by the caller and freed with scx_hits_free. Start it zeroed. */
typedef struct scx_hits {
  scx_hit* data;
  size_t len;
  size_t cap;
  /* Set when a hit could not be stored; the query then fails with SCX_ERR_HIT_BUFFER. */
  int overflow;
} scx_hits;

/* The nearest hit of one line; prim is SCX_NO_LINE (all ones) when the line hits nothing. */
typedef struct scx_first_hit {
  float t;
  uint32_t prim;
} scx_first_hit;

/* A line prepared for the watertight triangle test (Woop, Benthin, Wald, JCGT 2013): the axis permutation
 * and shear that map its direction onto +z. Internal; in the header for the size check. */
typedef struct scx_sheared {
  float org[3];
  float dir[3]; /* for the f64 distance of a grazing crossing */
  int kx, ky, kz;
  float sx, sy, sz;
} scx_sheared;

/* The per-query state. The Embree context must be the first member: Embree passes a pointer to it to the
 * intersect callback, which casts it back to the whole struct. Internal; in the header only so the
 * bindings' size can be checked. */
typedef struct scx_query {
  SCX_RTC_CONTEXT rtc;
#if SCX_EMBREE_V4
  struct RTCIntersectArguments args;
#endif
  const float* triangles;    /* the scene's original triangles, 9 floats each */
  uint32_t n_triangles;
  const scx_line* lines;     /* the batch, indexed by ray id */
  const scx_sheared* sheared; /* the batch prepared for the watertight test, indexed by ray id */
  uint32_t n_lines;          /* ray ids at or above this are not lines of the batch */
  scx_hits* hits;            /* all-hits queries: where candidates are appended, decided after the traversal */
  scx_first_hit* first;      /* first-hit queries: the nearest hit so far of each line */
  int bad_ray_id;            /* set by the callback on a foreign ray id or primitive */
} scx_query;

/* sizeof/_Alignof of every struct shared with Rust, as this C compiler sees them, and RTC_VERSION. Rust
 * compares them with its bindings: bindings made from other headers than the ones compiled against
 * would let Embree write past Rust's structs. */
typedef struct scx_layout {
  size_t ray;             /* struct RTCRay */
  size_t hit;             /* struct RTCHit */
  size_t rayhit;          /* struct RTCRayHit */
  size_t rayhit4;         /* struct RTCRayHit4 */
  size_t rayhit8;         /* struct RTCRayHit8 */
  size_t rayhit16;        /* struct RTCRayHit16 */
  size_t align_rayhit4;   /* _Alignof(struct RTCRayHit4) */
  size_t align_rayhit8;   /* _Alignof(struct RTCRayHit8) */
  size_t align_rayhit16;  /* _Alignof(struct RTCRayHit16) */
  size_t context;         /* RTCIntersectContext (v3) or RTCRayQueryContext (v4) */
  size_t arguments;       /* RTCIntersectArguments (v4); 0 with Embree 3 */
  size_t line;            /* scx_line */
  size_t hit_record;      /* scx_hit */
  size_t hits;            /* scx_hits */
  size_t first_hit;       /* scx_first_hit */
  size_t query;           /* scx_query */
  size_t sheared;         /* scx_sheared */
  size_t layout;          /* scx_layout */
  int32_t version;        /* RTC_VERSION of the headers compiled against, e.g. 31305 */
} scx_layout;

/* Fills *out with this shim's view of the shared structs. */
void scx_get_layout(scx_layout* out);

/* Takes the last error recorded on the calling thread: returns its code (SCX_OK if none) and copies its
 * message, NUL-terminated and truncated to len bytes, into buf (if buf is not NULL). Clears it. */
int scx_take_error(char* buf, size_t len);

/* Creates a device (config may be NULL) with an error callback that records errors for scx_take_error. */
int scx_device_new(const char* config, scx_device** out);
/* Releases a device; the scenes made from it keep Embree's device alive until they are released. */
void scx_device_release(scx_device* device);
/* The packet widths this device traces natively, as a bit set of 4, 8 and 16 (e.g. 4|8|16 = 28). */
uint32_t scx_device_packet_widths(const scx_device* device);
/* Embree's version as the running library reports it. */
void scx_device_version(const scx_device* device, int* major, int* minor, int* patch);

/* Builds and commits a robust scene of n_triangles triangles: n_vertices float3 positions and n_triangles
 * uint3 vertex indices (copied). Every index must be below n_vertices.
 *
 * Embree never tests the triangles itself: its own test (robust mode) can miss every triangle around a
 * vertex, or one face of a convex edge, when a line passes within rounding distance, and a triangle
 * inflated within its plane gives no margin across it (lines at small angles to the plane got lost).
 * So Embree gets each triangle's box, grown by 1/65536 of the scene's size on every side as in the
 * pure-Rust tracer, as a user geometry: the triangles whose boxes a line crosses are a superset of the
 * true hits at any angle, and each is decided, and its distance computed, by the watertight test on the
 * original triangle. The hits are exactly that test's, which is watertight at edges and vertices alike. */
int scx_scene_new(scx_device* device, const float* positions, uint32_t n_vertices, const uint32_t* indices,
                  uint32_t n_triangles, scx_scene** out);
/* Releases a scene. */
void scx_scene_release(scx_scene* scene);

/* Every intersection of n lines with the scene, appended to out as {t, prim, line}, in traversal order;
 * t and the hit decision come from the watertight test, identical for single lines and packets (Embree's
 * candidates are recorded during the traversal and decided after it, in one pass over the batch).
 * width 1 traces line by line (rtcIntersect1); 4, 8 or 16 traces packets of that many adjacent lines
 * (rtcIntersect4/8/16, native widths only), the last packet padded with inactive lanes. n must be below
 * SCX_NO_LINE. scratch is the caller's room for n prepared lines (its contents are overwritten): a caller
 * that keeps it, and out, from batch to batch allocates nothing per batch. Safe to call from several
 * threads at once with different out and scratch buffers. */
int scx_all_hits(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width,
                 scx_sheared* scratch, scx_hits* out);

/* The nearest hit of each of n lines (by the watertight test), written to out[0..n]; width and scratch
 * as for scx_all_hits. */
int scx_first_hits(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width,
                   scx_sheared* scratch, scx_first_hit* out);

/* Frees a hit buffer's storage and zeroes it. */
void scx_hits_free(scx_hits* hits);

#ifdef __cplusplus
}
#endif

#endif /* SCX_EMBREE_H */
