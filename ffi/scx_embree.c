/* scx_embree.c: see scx_embree.h. Works with Embree 3 and Embree 4 (SCX_EMBREE_V4). */

#include "scx_embree.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(_MSC_VER)
#define SCX_THREAD_LOCAL __declspec(thread)
#define SCX_ALIGN(n) __declspec(align(n))
#else
#define SCX_THREAD_LOCAL _Thread_local
#define SCX_ALIGN(n) __attribute__((aligned(n)))
#endif

#if SCX_EMBREE_V4
/* Without the scene flag, packet queries run kernels that never call the argument filter. */
#define SCX_SCENE_FLAGS (RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS)
#else
#define SCX_SCENE_FLAGS (RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION)
#endif

struct scx_device {
  RTCDevice rtc;
  uint32_t widths; /* native packet widths, a bit set of 4, 8, 16 */
};

struct scx_scene {
  RTCScene rtc;
  uint32_t widths; /* copied from the device: checked on every query */
};

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
  out->filter_args = sizeof(struct RTCFilterFunctionNArguments);
  out->line = sizeof(scx_line);
  out->hit_record = sizeof(scx_hit);
  out->hits = sizeof(scx_hits);
  out->first_hit = sizeof(scx_first_hit);
  out->query = sizeof(scx_query);
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

/* Copies the mesh into Embree-owned buffers and attaches it as geometry 0 (primID = triangle index). */
static int attach_triangles(RTCDevice device, RTCScene scene, const float* positions, uint32_t n_vertices,
                            const uint32_t* indices, uint32_t n_triangles) {
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (!geometry) return fail(RTC_ERROR_UNKNOWN, "rtcNewGeometry failed");
  /* Embree reads the last vertex with a 16-byte load, so the buffer needs 4 bytes past the last float3.
   * Some Embree 3 releases get the over-allocation of rtcSetNewGeometryBuffer wrong for a 12-byte stride,
   * so ask for one spare (zeroed, never indexed) vertex instead of relying on it. */
  float* vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                            3 * sizeof(float), (size_t)n_vertices + 1);
  uint32_t* triangles = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                3 * sizeof(uint32_t), n_triangles);
  if (!vertices || !triangles) {
    rtcReleaseGeometry(geometry);
    return fail(RTC_ERROR_OUT_OF_MEMORY, "rtcSetNewGeometryBuffer failed");
  }
  memcpy(vertices, positions, (size_t)n_vertices * 3 * sizeof(float));
  memset(vertices + (size_t)n_vertices * 3, 0, 3 * sizeof(float));
  memcpy(triangles, indices, (size_t)n_triangles * 3 * sizeof(uint32_t));
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  /* The scene holds its own reference now. */
  rtcReleaseGeometry(geometry);
  return last_code;
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

  scx_scene* scene = calloc(1, sizeof *scene);
  if (!scene) return fail(RTC_ERROR_OUT_OF_MEMORY, "scx_scene_new: out of memory");
  scene->widths = device->widths;
  scene->rtc = rtcNewScene(device->rtc);
  if (!scene->rtc) {
    free(scene);
    return fail(RTC_ERROR_UNKNOWN, "rtcNewScene failed");
  }
  rtcSetSceneFlags(scene->rtc, (enum RTCSceneFlags)SCX_SCENE_FLAGS);
  /* An empty scene is valid: it has no geometry and every query misses. */
  if (n_triangles > 0) {
    attach_triangles(device->rtc, scene->rtc, positions, n_vertices, indices, n_triangles);
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
/* The all-hits filter: record the candidate and reject it, so that one traversal visits every hit. */

static void collect_hits(const struct RTCFilterFunctionNArguments* args) {
  /* args->context points at q->rtc, the first member of q. */
  scx_query* q = (scx_query*)args->context;
  const unsigned int n = args->N;
  const float* ray = (const float*)args->ray;
  const unsigned int* ray_u = (const unsigned int*)args->ray;
  const unsigned int* hit_u = (const unsigned int*)args->hit;
  for (unsigned int i = 0; i < n; ++i) {
    if (args->valid[i] != -1) continue;
    /* Lanes are found by ray id, never by position: Embree may repack rays. */
    unsigned int line = ray_u[10 * n + i];
    if (line < q->n_lines) {
      /* During the callback the candidate's distance sits in the ray's tfar slot. */
      hits_push(q->hits, ray[8 * n + i], hit_u[5 * n + i], line);
    } else {
      q->bad_ray_id = 1;
    }
    args->valid[i] = 0;
  }
}

/* ---------------------------------------------------------------------------------------------------- */
/* Queries, with the v3/v4 differences kept in these few functions. */

static void query_init(scx_query* q, scx_hits* hits, uint32_t n_lines) {
  memset(q, 0, sizeof *q);
  RTCFilterFunctionN filter = hits ? collect_hits : NULL;
#if SCX_EMBREE_V4
  rtcInitRayQueryContext(&q->rtc);
  rtcInitIntersectArguments(&q->args);
  q->args.context = &q->rtc;
  if (filter) {
    q->args.filter = filter;
    q->args.flags = (enum RTCRayQueryFlags)(q->args.flags | RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER);
  }
#else
  rtcInitIntersectContext(&q->rtc);
  q->rtc.filter = filter;
#endif
  q->hits = hits;
  q->n_lines = n_lines;
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

static void store_first(scx_first_hit* out, float tfar, uint32_t geom, uint32_t prim) {
  const int hit = geom != RTC_INVALID_GEOMETRY_ID;
  out->t = hit ? tfar : 0.0f;
  out->prim = hit ? prim : SCX_NO_LINE;
}

static void packet_store_first(const scx_packet* p, uint32_t n, uint32_t count, scx_first_hit* out) {
  const float* ray = (const float*)p;
  const unsigned int* hit_u = (const unsigned int*)p + SCX_RAY_FIELDS * n;
  for (uint32_t i = 0; i < count; ++i) {
    store_first(&out[i], ray[8 * n + i], hit_u[6 * n + i], hit_u[5 * n + i]);
  }
}

static void trace_single(RTCScene scene, scx_query* q, const scx_line* lines, uint32_t n, scx_first_hit* first) {
  for (uint32_t k = 0; k < n; ++k) {
    struct RTCRayHit rh;
    ray_init(&rh, &lines[k], k);
    intersect1(scene, q, &rh);
    if (first) store_first(&first[k], rh.ray.tfar, rh.hit.geomID, rh.hit.primID);
  }
}

static void trace_packets(RTCScene scene, scx_query* q, const scx_line* lines, uint32_t n, uint32_t width,
                          scx_first_hit* first) {
  scx_packet packet; /* the union carries the 16/32/64-byte alignment of Embree's packet types */
  SCX_ALIGN(64) int valid[16];
  for (uint64_t base = 0; base < n; base += width) {
    const uint32_t count = (uint32_t)(n - base < width ? n - base : width);
    packet_fill(&packet, valid, width, lines + base, (uint32_t)base, count);
    intersect_packet(scene, q, valid, &packet, width);
    if (first) packet_store_first(&packet, width, count, first + base);
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

static void trace(const scx_scene* scene, scx_query* q, const scx_line* lines, uint32_t n, uint32_t width,
                  scx_first_hit* first) {
  if (width == 1) {
    trace_single(scene->rtc, q, lines, n, first);
  } else {
    trace_packets(scene->rtc, q, lines, n, width, first);
  }
}

int scx_all_hits(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width, scx_hits* out) {
  clear_error();
  if (!out) return fail(SCX_ERR_INVALID, "null hit buffer");
  if (check_query(scene, lines, n, width) != SCX_OK) return last_code;
  /* Most lines of a closed scene cross it a few times: start with room for two hits a line. */
  if (!hits_reserve(out, out->len + (size_t)n * 2 + 16)) out->overflow = 1;
  scx_query q;
  query_init(&q, out, n);
  if (!out->overflow) trace(scene, &q, lines, n, width, NULL);
  if (q.bad_ray_id) return fail(SCX_ERR_RAY_ID, "Embree reported a hit for a ray id outside the batch");
  if (out->overflow) return fail(SCX_ERR_HIT_BUFFER, "out of memory growing the hit buffer (%zu hits)", out->len);
  return last_code;
}

int scx_first_hits(const scx_scene* scene, const scx_line* lines, uint32_t n, uint32_t width,
                   scx_first_hit* out) {
  clear_error();
  if (n > 0 && !out) return fail(SCX_ERR_INVALID, "null output array");
  if (check_query(scene, lines, n, width) != SCX_OK) return last_code;
  scx_query q;
  query_init(&q, NULL, n);
  trace(scene, &q, lines, n, width, out);
  return last_code;
}
