/* scx_embree.c: see scx_embree.h. Works with Embree 3 and Embree 4 (SCX_EMBREE_V4). */

#include "scx_embree.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(_MSC_VER)
#define SCX_THREAD_LOCAL __declspec(thread)
#define SCX_ALIGN(n) __declspec(align(n))
#define SCX_PREFETCH(p) ((void)(p))
#else
#define SCX_THREAD_LOCAL _Thread_local
#define SCX_ALIGN(n) __attribute__((aligned(n)))
#define SCX_PREFETCH(p) __builtin_prefetch(p)
#endif

/* Robust box tests: the margin would cover Embree's fast ones too, but robust mode costs nothing measurable
 * on boxes, and keeps Embree's own rounding out of the argument. No filter flags: nothing is filtered,
 * the user geometry's intersect callback sees every candidate. */
#define SCX_SCENE_FLAGS (RTC_SCENE_FLAG_ROBUST)

struct scx_device {
  RTCDevice rtc;
  uint32_t widths; /* native packet widths, a bit set of 4, 8, 16 */
};

struct scx_scene {
  RTCScene rtc;
  uint32_t widths;    /* copied from the device: checked on every query */
  float* triangles;   /* the original triangles, 9 floats each, for the watertight test */
  uint32_t n_triangles;
  float margin;       /* how far each triangle's box reaches beyond it */
};

/* Every triangle's box grows on each side by the scene's size (the largest side of its bounding box) over
 * this, as in the pure-Rust tracer (margin() in src/trace/rust/bvh.rs, the same f32 operations): at least
 * 1.7e-5 in tracing space, where the scene fills the unit sphere. A box holds every point within the
 * margin of its triangle, in every direction. The watertight test sees the line through the triangle's
 * corners relative to the line's origin, rounded to f32: ~1e-6 for origins a few units away, and Embree's
 * box tests round as little. So a line the test says hits a triangle passes well inside the triangle's
 * box, and Embree proposes it, whatever the angle between line and triangle. */
#define SCX_MARGIN_DIVISOR 65536.0f

/* ---------------------------------------------------------------------------------------------------- */
/* Errors. Embree calls the error callback on the thread whose API call failed, so a thread-local record
 * gives each thread its own errors without locks, and scx_take_error reads them right after the call. */

static SCX_THREAD_LOCAL int last_code = SCX_OK;
static SCX_THREAD_LOCAL char last_message[512];

static void clear_error(void) {
  last_code = SCX_OK;
  last_message[0] = '\0';
}

/* Records an error unless one is already recorded for the current call: the first is the cause, later
 * ones are usually its consequences. Returns the recorded code. */
static int fail(int code, const char* format, ...) {
  if (last_code == SCX_OK) {
    va_list args;
    va_start(args, format);
    vsnprintf(last_message, sizeof last_message, format, args);
    va_end(args);
    last_code = code;
  }
  return last_code;
}

static void on_embree_error(void* user, enum RTCError code, const char* message) {
  (void)user;
  fail((int)code, "%s", message ? message : "(no message)");
}

int scx_take_error(char* buf, size_t len) {
  int code = last_code;
  if (buf && len > 0) {
    snprintf(buf, len, "%s", last_message);
  }
  clear_error();
  return code;
}

/* ---------------------------------------------------------------------------------------------------- */
/* Layout checks. The packet code below indexes RTCRayHitN as Embree's RTCRayN/RTCHitN accessors do (field
 * f of lane i at [f * N + i], ray fields first, then the hit): make sure the headers agree. */

#define SCX_RAY_FIELDS 12
_Static_assert(offsetof(struct RTCRayHit4, hit) == SCX_RAY_FIELDS * 4 * sizeof(float), "RTCRayHit4 layout");
_Static_assert(offsetof(struct RTCRayHit8, hit) == SCX_RAY_FIELDS * 8 * sizeof(float), "RTCRayHit8 layout");
_Static_assert(offsetof(struct RTCRayHit16, hit) == SCX_RAY_FIELDS * 16 * sizeof(float), "RTCRayHit16 layout");
_Static_assert(offsetof(struct RTCRayHit8, ray.tfar) == 8 * 8 * sizeof(float), "RTCRay8 tfar");
_Static_assert(offsetof(struct RTCRayHit8, ray.id) == 10 * 8 * sizeof(float), "RTCRay8 id");
_Static_assert(offsetof(struct RTCRayHit8, hit.primID) - offsetof(struct RTCRayHit8, hit) == 5 * 8 * 4,
               "RTCHit8 primID");
_Static_assert(offsetof(struct RTCRayHit8, hit.geomID) - offsetof(struct RTCRayHit8, hit) == 6 * 8 * 4,
               "RTCHit8 geomID");
_Static_assert(offsetof(struct RTCRayHit8, hit.instID) - offsetof(struct RTCRayHit8, hit) == 7 * 8 * 4,
               "RTCHit8 instID");
_Static_assert(sizeof(scx_hit) == 12, "scx_hit must match Rust's RawHit");
_Static_assert(offsetof(scx_query, rtc) == 0, "the Embree context must come first in scx_query");

void scx_get_layout(scx_layout* out) {
  memset(out, 0, sizeof *out);
  out->ray = sizeof(struct RTCRay);
  out->hit = sizeof(struct RTCHit);
  out->rayhit = sizeof(struct RTCRayHit);
  out->rayhit4 = sizeof(struct RTCRayHit4);
  out->rayhit8 = sizeof(struct RTCRayHit8);
  out->rayhit16 = sizeof(struct RTCRayHit16);
  out->align_rayhit4 = _Alignof(struct RTCRayHit4);
  out->align_rayhit8 = _Alignof(struct RTCRayHit8);
  out->align_rayhit16 = _Alignof(struct RTCRayHit16);
  out->context = sizeof(SCX_RTC_CONTEXT);
#if SCX_EMBREE_V4
  out->arguments = sizeof(struct RTCIntersectArguments);
#endif
  out->line = sizeof(scx_line);
  out->hit_record = sizeof(scx_hit);
  out->hits = sizeof(scx_hits);
  out->first_hit = sizeof(scx_first_hit);
  out->query = sizeof(scx_query);
  out->sheared = sizeof(scx_sheared);
  out->layout = sizeof(scx_layout);
  out->version = RTC_VERSION;
}

/* ---------------------------------------------------------------------------------------------------- */
/* Device. */

static uint32_t native_widths(RTCDevice device) {
  uint32_t widths = 0;
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED)) widths |= 4;
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) widths |= 8;
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) widths |= 16;
  return widths;
}

int scx_device_new(const char* config, scx_device** out) {
  clear_error();
  if (!out) return fail(SCX_ERR_INVALID, "scx_device_new: null output pointer");
  *out = NULL;
  scx_device* device = calloc(1, sizeof *device);
  if (!device) return fail(RTC_ERROR_OUT_OF_MEMORY, "scx_device_new: out of memory");
  device->rtc = rtcNewDevice(config);
  if (!device->rtc) {
    /* No callback can be registered before the device exists: ask for the creation error. */
    int code = (int)rtcGetDeviceError(NULL);
    free(device);
    return fail(code != RTC_ERROR_NONE ? code : RTC_ERROR_UNKNOWN, "rtcNewDevice failed");
  }
  rtcSetDeviceErrorFunction(device->rtc, on_embree_error, NULL);
  device->widths = native_widths(device->rtc);
  *out = device;
  return SCX_OK;
}

void scx_device_release(scx_device* device) {
  if (!device) return;
  rtcReleaseDevice(device->rtc);
  free(device);
}

uint32_t scx_device_packet_widths(const scx_device* device) {
  return device ? device->widths : 0;
}

void scx_device_version(const scx_device* device, int* major, int* minor, int* patch) {
  *major = (int)rtcGetDeviceProperty(device->rtc, RTC_DEVICE_PROPERTY_VERSION_MAJOR);
  *minor = (int)rtcGetDeviceProperty(device->rtc, RTC_DEVICE_PROPERTY_VERSION_MINOR);
  *patch = (int)rtcGetDeviceProperty(device->rtc, RTC_DEVICE_PROPERTY_VERSION_PATCH);
}

/* ---------------------------------------------------------------------------------------------------- */
/* Scene. */

static int check_indices(const uint32_t* indices, uint32_t n_triangles, uint32_t n_vertices) {
  for (size_t k = 0; k < (size_t)n_triangles * 3; ++k) {
    if (indices[k] >= n_vertices) {
      return fail(SCX_ERR_INVALID, "triangle %zu refers to vertex %u, but the scene has %u vertices", k / 3,
                  indices[k], n_vertices);
    }
  }
  return SCX_OK;
}

/* Embree's bounds callback: the box of triangle primID, grown by the margin. */
static void triangle_bounds(const struct RTCBoundsFunctionArguments* args) {
  const scx_scene* scene = (const scx_scene*)args->geometryUserPtr;
  const float* v = scene->triangles + 9 * (size_t)args->primID;
  const float m = scene->margin;
  struct RTCBounds* b = args->bounds_o;
  b->lower_x = fminf(fminf(v[0], v[3]), v[6]) - m;
  b->lower_y = fminf(fminf(v[1], v[4]), v[7]) - m;
  b->lower_z = fminf(fminf(v[2], v[5]), v[8]) - m;
  b->upper_x = fmaxf(fmaxf(v[0], v[3]), v[6]) + m;
  b->upper_y = fmaxf(fmaxf(v[1], v[4]), v[7]) + m;
  b->upper_z = fmaxf(fmaxf(v[2], v[5]), v[8]) + m;
}

static void propose(const struct RTCIntersectFunctionNArguments* args);

/* Attaches the scene's triangles as geometry 0 (primID = triangle index): a user geometry whose bounds are
 * the triangles' grown boxes and whose intersect callback, propose(), hands each candidate to the
 * watertight test. Not Embree's own triangles, even inflated: inflating a triangle within its plane gives
 * no margin across the plane, and a line at a small angle a to the plane sees every error across it
 * (the f32 rounding of the inflated corners, which tilts the plane, and the rounding of Embree's and of
 * the watertight test) magnified by 1 / sin a within the plane, past any in-plane margin near an edge.
 * That lost crossings of ~4% of lines grazing tilted triangles at vertices and edges, and ~2e-3 of lines
 * aimed at the vertices of @sphere:5 in random directions. */
static int attach_triangles(RTCDevice device, scx_scene* scene) {
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  if (!geometry) return fail(RTC_ERROR_UNKNOWN, "rtcNewGeometry failed");
  rtcSetGeometryUserPrimitiveCount(geometry, scene->n_triangles);
  rtcSetGeometryUserData(geometry, scene);
  rtcSetGeometryBoundsFunction(geometry, triangle_bounds, NULL);
  rtcSetGeometryIntersectFunction(geometry, propose);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene->rtc, geometry);
  /* The scene holds its own reference now. */
  rtcReleaseGeometry(geometry);
  return last_code;
}

/* Copies the triangles' corners out of the indexed mesh. */
static void gather_triangles(float* out, const float* positions, const uint32_t* indices, uint32_t n) {
  for (size_t i = 0; i < (size_t)n * 3; ++i) {
    for (int a = 0; a < 3; ++a) out[3 * i + a] = positions[3 * (size_t)indices[i] + a];
  }
}

/* The boxes' margin: the largest side of the vertices' bounding box over SCX_MARGIN_DIVISOR (1 over it for
 * an empty or flat-as-a-point scene), in the pure-Rust tracer's f32 operations. */
static float box_margin(const float* positions, uint32_t n_vertices) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n_vertices; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = fminf(lo[a], positions[3 * i + a]);
      hi[a] = fmaxf(hi[a], positions[3 * i + a]);
    }
  }
  float size = 0.0f;
  for (int a = 0; a < 3; ++a) size = fmaxf(size, hi[a] - lo[a]);
  return (size > 0.0f ? size : 1.0f) / SCX_MARGIN_DIVISOR;
}

int scx_scene_new(scx_device* device, const float* positions, uint32_t n_vertices, const uint32_t* indices,
                  uint32_t n_triangles, scx_scene** out) {
  clear_error();
  if (!out || !device) return fail(SCX_ERR_INVALID, "scx_scene_new: null device or output pointer");
  *out = NULL;
  if (n_triangles > 0 && (!positions || !indices))
    return fail(SCX_ERR_INVALID, "scx_scene_new: null vertex or index array");
  if (n_vertices == UINT32_MAX) return fail(SCX_ERR_INVALID, "scx_scene_new: too many vertices");
  if (check_indices(indices, n_triangles, n_vertices) != SCX_OK) return last_code;

  if (n_triangles > UINT32_MAX / 3) return fail(SCX_ERR_INVALID, "scx_scene_new: too many triangles");
  scx_scene* scene = calloc(1, sizeof *scene);
  if (!scene) return fail(RTC_ERROR_OUT_OF_MEMORY, "scx_scene_new: out of memory");
  scene->widths = device->widths;
  scene->n_triangles = n_triangles;
  scene->triangles = malloc(((size_t)n_triangles * 9 + 1) * sizeof(float));
  if (!scene->triangles) {
    free(scene);
    return fail(RTC_ERROR_OUT_OF_MEMORY, "scx_scene_new: out of memory");
  }
  gather_triangles(scene->triangles, positions, indices, n_triangles);
  scene->margin = box_margin(positions, n_vertices);
  scene->rtc = rtcNewScene(device->rtc);
  if (!scene->rtc) {
    free(scene);
    return fail(RTC_ERROR_UNKNOWN, "rtcNewScene failed");
  }
  rtcSetSceneFlags(scene->rtc, (enum RTCSceneFlags)SCX_SCENE_FLAGS);
  /* An empty scene is valid: it has no geometry and every query misses. */
  if (n_triangles > 0) {
    attach_triangles(device->rtc, scene);
  }
  if (last_code == SCX_OK) rtcCommitScene(scene->rtc);
  if (last_code != SCX_OK) {
    scx_scene_release(scene);
    return last_code;
  }
  *out = scene;
  return SCX_OK;
}

void scx_scene_release(scx_scene* scene) {
  if (!scene) return;
  if (scene->rtc) rtcReleaseScene(scene->rtc);
  free(scene->triangles);
  free(scene);
}

/* ---------------------------------------------------------------------------------------------------- */
/* Hit buffer. */

static int hits_reserve(scx_hits* hits, size_t cap) {
  if (cap <= hits->cap) return 1;
  if (cap > SIZE_MAX / sizeof(scx_hit)) return 0;
  scx_hit* data = realloc(hits->data, cap * sizeof(scx_hit));
  if (!data) return 0;
  hits->data = data;
  hits->cap = cap;
  return 1;
}

static void hits_push(scx_hits* hits, float t, uint32_t prim, uint32_t line) {
  if (hits->len == hits->cap && !hits_reserve(hits, hits->cap < 512 ? 1024 : hits->cap * 2)) {
    /* Never drop a hit silently: the query reports the overflow. */
    hits->overflow = 1;
    return;
  }
  scx_hit* h = &hits->data[hits->len++];
  h->t = t;
  h->prim = prim;
  h->line = line;
}

void scx_hits_free(scx_hits* hits) {
  if (!hits) return;
  free(hits->data);
  memset(hits, 0, sizeof *hits);
}

/* ---------------------------------------------------------------------------------------------------- */
/* The watertight ray/triangle test of Woop, Benthin and Wald (JCGT 2(1), 2013), with the same operations
 * in the same order as the pure-Rust tracer (src/trace/rust/watertight.rs), so both give bit-identical
 * hits. Needs IEEE single precision without FMA contraction (the build passes -ffp-contract=off): the
 * edge functions of a shared edge must come out exactly opposite in its two triangles. */

/* The axes are picked by table, not by branches: the dominant axis of a random direction, and its sign,
 * cannot be predicted, and the branches of the obvious code cost ~6% of an all-hits trace of @cube:30. */
static void shear_line(scx_sheared* r, const scx_line* line) {
  /* kz, the dominant axis (the last of equals), by (|dx| > |dy|) << 2 | (|dx| > |dz|) << 1 | (|dy| > |dz|) */
  static const unsigned char kz_of[8] = {2, 1, 2, 1, 2, 2, 0, 0};
  /* kx and ky by 2 kz + (d[kz] < 0): the next two axes, swapped when the dominant component is negative,
   * to keep the winding */
  static const unsigned char kx_of[6] = {1, 2, 2, 0, 0, 1};
  static const unsigned char ky_of[6] = {2, 1, 0, 2, 1, 0};
  const float* d = line->dir;
  const float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
  const unsigned kz = kz_of[((unsigned)(ax > ay) << 2) | ((unsigned)(ax > az) << 1) | (unsigned)(ay > az)];
  const unsigned neg = (unsigned)(d[kz] < 0.0f);
  const unsigned kx = kx_of[2 * kz + neg];
  const unsigned ky = ky_of[2 * kz + neg];
  memcpy(r->org, line->org, sizeof r->org);
  memcpy(r->dir, line->dir, sizeof r->dir);
  r->kx = (int)kx;
  r->ky = (int)ky;
  r->kz = (int)kz;
  r->sx = d[kx] / d[kz];
  r->sy = d[ky] / d[kz];
  r->sz = 1.0f / d[kz];
}

/* The bounds of grazing crossings (src/trace/rust/watertight.rs: GRAZING_BOUND, NOISY_DETERMINANT,
 * CLEAR_OF_EDGES). */
#define SCX_GRAZING_BOUND 4.0f
#define SCX_NOISY_DETERMINANT 16.0f
#define SCX_CLEAR_OF_EDGES 32.0f
/* src/trace/rust/watertight.rs: EXACT_SIGN (f32::EPSILON). */
#define SCX_EXACT_SIGN FLT_EPSILON

static inline float max_f(float a, float b) { return a > b ? a : b; }
static inline float min_f(float a, float b) { return a < b ? a : b; }

/* The scale of the edge functions' rounding: edge_error of src/trace/rust/watertight.rs, in its order. */
static float edge_error(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy, float cz) {
  const float x = max_f(max_f(max_f(max_f(max_f(fabsf(ax), fabsf(ay)), fabsf(bx)), fabsf(by)), fabsf(cx)), fabsf(cy));
  const float z = max_f(max_f(fabsf(az), fabsf(bz)), fabsf(cz));
  return (x + z) * x;
}

/* Whether the f32 t of an accepted crossing may be more than SCX_GRAZING_BOUND ulps off: the f32
 * operations of ShearedRay::grazing, in its order. */
static int grazing(const scx_sheared* r, float scale, float az, float bz, float cz, float det, float t) {
  const float spread = max_f(max_f(az, bz), cz) - min_f(min_f(az, bz), cz);
  const float d = fabsf(det);
  return d <= (SCX_NOISY_DETERMINANT * FLT_EPSILON) * scale ||
         scale * spread * fabsf(r->sz) > SCX_GRAZING_BOUND * d * max_f(fabsf(t), 1.0f);
}

/* The distance of a grazing crossing of triangle (a, b, c) in f64: for a crossing clear of the edges
 * (interior), the distance to its plane, else (or for a plane parallel to the line) t32, kept within the
 * stretch of the line inside the triangle's box. The operations of ShearedRay::grazing_t, in its order
 * (see there why). */
static float grazing_t(const scx_sheared* r, const float* a, const float* b, const float* c, float t32,
                       int interior) {
  const int kx = r->kx, ky = r->ky, kz = r->kz;
  const double ox = (double)r->org[kx], oy = (double)r->org[ky], oz = (double)r->org[kz];
  const double ra[3] = {(double)a[kx] - ox, (double)a[ky] - oy, (double)a[kz] - oz};
  const double rb[3] = {(double)b[kx] - ox, (double)b[ky] - oy, (double)b[kz] - oz};
  const double rc[3] = {(double)c[kx] - ox, (double)c[ky] - oy, (double)c[kz] - oz};
  const double dir[3] = {(double)r->dir[kx], (double)r->dir[ky], (double)r->dir[kz]};
  const double e1[3] = {rb[0] - ra[0], rb[1] - ra[1], rb[2] - ra[2]};
  const double e2[3] = {rc[0] - ra[0], rc[1] - ra[1], rc[2] - ra[2]};
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double along = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
  const double plane = (n[0] * ra[0] + n[1] * ra[1] + n[2] * ra[2]) / along;
  double t = interior && isfinite(plane) ? plane : (double)t32;
  double enter = -INFINITY, exit = INFINITY;
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.0) continue;
    double lo = ra[k] < rb[k] ? ra[k] : rb[k];
    lo = rc[k] < lo ? rc[k] : lo;
    double hi = ra[k] > rb[k] ? ra[k] : rb[k];
    hi = rc[k] > hi ? rc[k] : hi;
    const double t1 = lo / dir[k], t2 = hi / dir[k];
    const double near = t1 < t2 ? t1 : t2, far = t1 < t2 ? t2 : t1;
    if (near > enter) enter = near;
    if (far < exit) exit = far;
  }
  if (enter > exit) {
    t = 0.5 * (enter + exit);
  } else if (t < enter) {
    t = enter;
  } else if (t > exit) {
    t = exit;
  }
  return (float)t;
}

/* The edge function p q - r s as the f32 test computes it, and in *exact a double of its exact sign:
 * edge_function of src/trace/rust/watertight.rs, in its operations (see there why the sign is exact). */
static inline float edge_function(float p, float q, float r, float s, double* exact) {
  const float pq = p * q, rs = r * s;
  const float e = pq - rs;
  if (fabsf(e) > SCX_EXACT_SIGN * (fabsf(pq) + fabsf(rs)) + FLT_MIN) {
    *exact = (double)e;
    return e;
  }
  *exact = (double)p * (double)q - (double)r * (double)s;
  return (float)*exact;
}

/* The sign of an edge function with the origin moved by (epsilon, epsilon^2) when it is exactly 0:
 * perturbed_sign of src/trace/rust/watertight.rs. */
static inline int perturbed_sign(double exact, float dx, float dy) {
  if (exact != 0.0) return (exact > 0.0) - (exact < 0.0);
  if (dx != 0.0f) return (dx > 0.0f) - (dx < 0.0f);
  return (dy > 0.0f) - (dy < 0.0f);
}

/* Whether the line hits triangle tri (9 floats) at t in [t_min, t_max]; t in *t_out. */
static int watertight_hit(const scx_sheared* r, const float* tri, float t_min, float t_max, float* t_out) {
  /* Relative to the origin, then sheared; only the components the shear reads are computed (each in the
   * same operations as computing the whole difference first). */
  const int kx = r->kx, ky = r->ky, kz = r->kz;
  const float ox = r->org[kx], oy = r->org[ky], oz = r->org[kz];
  const float *a = tri, *b = tri + 3, *c = tri + 6;
  const float az = a[kz] - oz, bz = b[kz] - oz, cz = c[kz] - oz;
  const float ax = (a[kx] - ox) - r->sx * az, ay = (a[ky] - oy) - r->sy * az;
  const float bx = (b[kx] - ox) - r->sx * bz, by = (b[ky] - oy) - r->sy * bz;
  const float cx = (c[kx] - ox) - r->sx * cz, cy = (c[ky] - oy) - r->sy * cz;
  double u_exact, v_exact, w_exact;
  const float u = edge_function(cx, by, cy, bx, &u_exact);
  const float v = edge_function(ax, cy, ay, cx, &v_exact);
  const float w = edge_function(bx, ay, by, ax, &w_exact);
  const int su = perturbed_sign(u_exact, cy - by, bx - cx);
  const int sv = perturbed_sign(v_exact, ay - cy, cx - ax);
  const int sw = perturbed_sign(w_exact, by - ay, ax - bx);
  if (!((su > 0 && sv > 0 && sw > 0) || (su < 0 && sv < 0 && sw < 0))) return 0;
  const float det = u + v + w;
  if (det == 0.0f) return 0;
  float t = (u * (r->sz * az) + v * (r->sz * bz) + w * (r->sz * cz)) / det;
  const float scale = edge_error(ax, ay, az, bx, by, bz, cx, cy, cz);
  if (grazing(r, scale, az, bz, cz, det, t)) {
    const float clear = (SCX_CLEAR_OF_EDGES * FLT_EPSILON) * scale;
    t = grazing_t(r, a, b, c, t, fabsf(u) > clear && fabsf(v) > clear && fabsf(w) > clear);
  }
  if (!(t >= t_min && t <= t_max)) return 0;
  *t_out = t;
  return 1;
}

/* Embree's candidates: each triangle whose box a ray of the query crosses. All hits: record the candidate,
 * to be decided after the traversal (decide_candidates), and report no hit, so that the traversal goes
 * on through every box. Deciding here instead made Embree wait, candidate after candidate, for the test
 * and for the cache miss on the original triangle: 30-40% of an all-hits trace of @cube:100 (120,000
 * triangles); decided afterwards, in one pass, the misses overlap. First hit: decide at once and report
 * true hits (shortening the ray, so Embree narrows its search to nearer boxes), keeping the nearest by the
 * watertight t, ties to the lower triangle index. */
static void propose(const struct RTCIntersectFunctionNArguments* args) {
  /* args->context points at q->rtc, the first member of q. */
  scx_query* q = (scx_query*)args->context;
  const uint32_t prim = args->primID;
  const unsigned int n = args->N;
  float* ray = (float*)args->rayhit;
  unsigned int* hit = (unsigned int*)args->rayhit + SCX_RAY_FIELDS * n;
  if (prim >= q->n_triangles) {
    q->bad_ray_id = 1;
    return;
  }
  for (unsigned int i = 0; i < n; ++i) {
    if (args->valid[i] != -1) continue;
    /* Lanes are found by ray id, never by position: Embree may repack rays. */
    const uint32_t line = ((const unsigned int*)ray)[10 * n + i];
    if (line >= q->n_lines) {
      q->bad_ray_id = 1;
      continue;
    }
    if (q->hits) {
      hits_push(q->hits, 0.0f, prim, line);
      continue;
    }
    float t;
    const float t_far = ray[8 * n + i];
    if (!watertight_hit(&q->sheared[line], q->triangles + 9 * (size_t)prim, 0.0f, t_far, &t)) continue;
    scx_first_hit* best = &q->first[line];
    if (best->prim == SCX_NO_LINE || t < best->t || (t == best->t && prim < best->prim)) {
      best->t = t;
      best->prim = prim;
    }
    /* Boxes reach past their triangle by the margin, so another triangle through the same point, at the
     * same t, is still proposed after tfar shrinks to t. */
    ray[8 * n + i] = t;
    hit[5 * n + i] = prim;
    hit[6 * n + i] = args->geomID;
  }
}

/* How many candidates ahead decide_candidates prefetches the original triangle. */
#define SCX_PREFETCH_AHEAD 8

/* Decides the candidates hits[from..len) recorded by propose() with the watertight test: keeps the
 * hits, in order, with their distances, and drops the rest. */
static void decide_candidates(const scx_query* q, size_t from) {
  scx_hit* data = q->hits->data;
  const size_t len = q->hits->len;
  size_t kept = from;
  for (size_t k = from; k < len; ++k) {
    if (k + SCX_PREFETCH_AHEAD < len) {
      /* A triangle's 36 bytes can straddle two cache lines. */
      const float* ahead = q->triangles + 9 * (size_t)data[k + SCX_PREFETCH_AHEAD].prim;
      SCX_PREFETCH(ahead);
      SCX_PREFETCH(ahead + 8);
    }
    const uint32_t line = data[k].line, prim = data[k].prim;
    float t;
    if (watertight_hit(&q->sheared[line], q->triangles + 9 * (size_t)prim, 0.0f, q->lines[line].t_max, &t)) {
      data[kept].t = t;
      data[kept].prim = prim;
      data[kept].line = line;
      ++kept;
    }
  }
  q->hits->len = kept;
}

/* ---------------------------------------------------------------------------------------------------- */
/* Queries, with the v3/v4 differences kept in these few functions. */

/* Prepares a query over a batch: all hits into `hits`, or first hits into `first`. */
static void query_init(scx_query* q, const scx_scene* scene, const scx_line* lines, const scx_sheared* sheared,
                       uint32_t n_lines, scx_hits* hits, scx_first_hit* first) {
  memset(q, 0, sizeof *q);
#if SCX_EMBREE_V4
  rtcInitRayQueryContext(&q->rtc);
  rtcInitIntersectArguments(&q->args);
  q->args.context = &q->rtc;
#else
  rtcInitIntersectContext(&q->rtc);
#endif
  q->triangles = scene->triangles;
  q->n_triangles = scene->n_triangles;
  q->lines = lines;
  q->sheared = sheared;
  q->n_lines = n_lines;
  q->hits = hits;
  q->first = first;
}

static void intersect1(RTCScene scene, scx_query* q, struct RTCRayHit* rayhit) {
#if SCX_EMBREE_V4
  rtcIntersect1(scene, rayhit, &q->args);
#else
  rtcIntersect1(scene, &q->rtc, rayhit);
#endif
}

typedef union scx_packet {
  struct RTCRayHit4 p4;
  struct RTCRayHit8 p8;
  struct RTCRayHit16 p16;
} scx_packet;

static void intersect_packet(RTCScene scene, scx_query* q, const int* valid, scx_packet* p, uint32_t width) {
#if SCX_EMBREE_V4
  switch (width) {
    case 4: rtcIntersect4(valid, scene, &p->p4, &q->args); break;
    case 8: rtcIntersect8(valid, scene, &p->p8, &q->args); break;
    default: rtcIntersect16(valid, scene, &p->p16, &q->args); break;
  }
#else
  switch (width) {
    case 4: rtcIntersect4(valid, scene, &q->rtc, &p->p4); break;
    case 8: rtcIntersect8(valid, scene, &q->rtc, &p->p8); break;
    default: rtcIntersect16(valid, scene, &q->rtc, &p->p16); break;
  }
#endif
}

static void ray_init(struct RTCRayHit* rh, const scx_line* line, uint32_t id) {
  rh->ray.org_x = line->org[0];
  rh->ray.org_y = line->org[1];
  rh->ray.org_z = line->org[2];
  rh->ray.tnear = 0.0f;
  rh->ray.dir_x = line->dir[0];
  rh->ray.dir_y = line->dir[1];
  rh->ray.dir_z = line->dir[2];
  rh->ray.time = 0.0f;
  rh->ray.tfar = line->t_max;
  rh->ray.mask = 0xFFFFFFFFu; /* Embree 4's default geometry mask is 1, not all ones */
  rh->ray.id = id;
  rh->ray.flags = 0;
  rh->hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* Padding lanes: besides valid[i] = 0, an empty interval (tfar < tnear), because Embree 3 ignores valid[]
 * at widths the CPU has no native kernel for. */
static const scx_line idle_line = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, -1.0f};

/* Fills lanes [0, count) with lines[0..count) (ray ids first + lane) and the rest with idle lanes. */
static void packet_fill(scx_packet* p, int* valid, uint32_t n, const scx_line* lines, uint32_t first,
                        uint32_t count) {
  float* ray = (float*)p;
  unsigned int* ray_u = (unsigned int*)p;
  unsigned int* hit_u = ray_u + SCX_RAY_FIELDS * n;
  for (uint32_t i = 0; i < n; ++i) {
    const int active = i < count;
    const scx_line* line = active ? &lines[i] : &idle_line;
    for (uint32_t a = 0; a < 3; ++a) {
      ray[a * n + i] = line->org[a];
      ray[(4 + a) * n + i] = line->dir[a];
    }
    ray[3 * n + i] = 0.0f;          /* tnear */
    ray[7 * n + i] = 0.0f;          /* time */
    ray[8 * n + i] = line->t_max;   /* tfar */
    ray_u[9 * n + i] = 0xFFFFFFFFu; /* mask */
    ray_u[10 * n + i] = active ? first + i : SCX_NO_LINE;
    ray_u[11 * n + i] = 0;          /* flags */
    hit_u[5 * n + i] = RTC_INVALID_GEOMETRY_ID; /* primID */
    hit_u[6 * n + i] = RTC_INVALID_GEOMETRY_ID; /* geomID */
    hit_u[7 * n + i] = RTC_INVALID_GEOMETRY_ID; /* instID[0] */
    valid[i] = active ? -1 : 0;
  }
}

/* Results arrive through propose() (in q), not in the ray structs. */
static void trace_single(RTCScene scene, scx_query* q, const scx_line* lines, uint32_t n) {
  for (uint32_t k = 0; k < n; ++k) {
    struct RTCRayHit rh;
    ray_init(&rh, &lines[k], k);
    intersect1(scene, q, &rh);
  }
}

static void trace_packets(RTCScene scene, scx_query* q, const scx_line* lines, uint32_t n, uint32_t width) {
  scx_packet packet; /* the union carries the 16/32/64-byte alignment of Embree's packet types */
  SCX_ALIGN(64) int valid[16];
  for (uint64_t base = 0; base < n; base += width) {
    const uint32_t count = (uint32_t)(n - base < width ? n - base : width);
    packet_fill(&packet, valid, width, lines + base, (uint32_t)base, count);
    intersect_packet(scene, q, valid, &packet, width);
  }
}

static int check_query(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width) {
  if (!scene || (n > 0 && !lines)) return fail(SCX_ERR_INVALID, "null scene or line array");
  if (n >= SCX_NO_LINE) return fail(SCX_ERR_INVALID, "too many lines in one batch: %u", n);
  const int native = (width == 4 || width == 8 || width == 16) && (scene->widths & width);
  if (width != 1 && !native) {
    return fail(SCX_ERR_INVALID, "packet width %u is not native on this device (native widths bit set: %u)",
                width, scene->widths);
  }
  return SCX_OK;
}

/* Prepares the batch for the watertight test (in the caller's scratch) and traces it; propose() delivers
 * the results into q (all hits: candidates, decided after the traversal). */
static int trace(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width,
                 scx_sheared* sheared, scx_hits* hits, scx_first_hit* first) {
  if (n > 0 && !sheared) return fail(SCX_ERR_INVALID, "null scratch for %u lines", n);
  for (uint32_t k = 0; k < n; ++k) shear_line(&sheared[k], &lines[k]);
  scx_query q;
  query_init(&q, scene, lines, sheared, n, hits, first);
  const size_t from = hits ? hits->len : 0;
  if (width == 1) {
    trace_single(scene->rtc, &q, lines, n);
  } else {
    trace_packets(scene->rtc, &q, lines, n, width);
  }
  if (hits) decide_candidates(&q, from);
  if (q.bad_ray_id) return fail(SCX_ERR_RAY_ID, "Embree reported a hit for a ray or primitive outside the batch");
  return last_code;
}

int scx_all_hits(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width,
                 scx_sheared* scratch, scx_hits* out) {
  clear_error();
  if (!out) return fail(SCX_ERR_INVALID, "null hit buffer");
  if (check_query(scene, lines, n, width) != SCX_OK) return last_code;
  /* Most lines of a closed scene cross it a few times: start with room for two hits a line. */
  if (!hits_reserve(out, out->len + (size_t)n * 2 + 16)) out->overflow = 1;
  if (!out->overflow) trace(scene, lines, n, width, scratch, out, NULL);
  if (out->overflow) return fail(SCX_ERR_HIT_BUFFER, "out of memory growing the hit buffer (%zu hits)", out->len);
  return last_code;
}

int scx_first_hits(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width,
                   scx_sheared* scratch, scx_first_hit* out) {
  clear_error();
  if (n > 0 && !out) return fail(SCX_ERR_INVALID, "null output array");
  if (check_query(scene, lines, n, width) != SCX_OK) return last_code;
  for (uint32_t k = 0; k < n; ++k) {
    out[k].t = 0.0f;
    out[k].prim = SCX_NO_LINE;
  }
  return trace(scene, lines, n, width, scratch, NULL, out);
}
