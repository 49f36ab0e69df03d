/* embree_whitted.c: the peer of raytree's peer benchmark (benches/peer.rs). A Whitted ray
 * tracer over Embree 3 (single rays: rtcIntersect1 for camera, reflected and refracted rays,
 * rtcOccluded1 for shadow rays) that renders the scene `benches/peer.rs` hands it with the same
 * camera, materials, recursion, shadow-ray rule and ray-origin offsets as raytree's
 * `src/trace/`, on N pthreads over 32x32 tiles taken from an atomic counter.
 *
 * Usage: embree_whitted [--spheres builtin|user] [--quality low|medium|high] [--frames K]
 *                       [--ftz 0|1] [--robust 0|1] SCENE.bin THREADS [IMAGE.f32]
 *
 * --spheres builtin (the default) gives the spheres to Embree as its own sphere geometry
 *   (RTC_GEOMETRY_TYPE_SPHERE_POINT, a float4 centre and radius each): Embree's ray-sphere
 *   intersector, the fast path an Embree user takes. `user` is an Embree user geometry whose
 *   callback is raytree's robust (Ray Tracing Gems ch. 7) root pair.
 * --quality sets the scene's and every geometry's build quality (default high: the triangles'
 *   BVH with spatial splits, as an Embree user after render speed chooses).
 * --robust 1 sets RTC_SCENE_FLAG_ROBUST (Embree's watertight mode: no ray slips between two
 *   triangles that share an edge, at some cost in speed); the default 0 leaves the scene flags
 *   RTC_SCENE_FLAG_NONE (not robust, not dynamic, no filter callbacks), Embree's fastest.
 * --frames K renders the image K times after one build: frame 1 is the first frame, the rest
 *   are warm frames (default 1).
 * --ftz 1 sets flush-to-zero and denormals-are-zero on every tracing thread, as Embree's
 *   documentation asks (default 0).
 *
 * Prints `key value` lines: load and build seconds, `frame_secs` (each frame's render phase),
 * `render_secs` (frame 1), rays by kind of one frame, Mrays/s, memory. Writes the last frame's
 * linear RGB image as raw little-endian f32 when IMAGE is given.
 *
 * Build: cc -O3 -march=native -ffp-contract=off embree_whitted.c -lembree3 -lpthread -lm
 * (no FMA contraction: the shading rounds as raytree's does). */
#include <embree3/rtcore.h>
#if defined(__SSE3__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct { float x, y, z; } vec3;

static inline vec3 v3(float x, float y, float z) { vec3 r = {x, y, z}; return r; }
static inline vec3 add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 scale(float s, vec3 a) { return v3(s * a.x, s * a.y, s * a.z); }
static inline vec3 neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline vec3 vabs(vec3 a) { return v3(fabsf(a.x), fabsf(a.y), fabsf(a.z)); }
static inline float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 cross(vec3 a, vec3 b) {
    return v3(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}
static inline float length(vec3 a) { return sqrtf(dot(a, a)); }
/* As glam: multiply by the reciprocal of the length. */
static inline vec3 normalize(vec3 a) { return scale(1.0f / length(a), a); }
static inline int is_zero(vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
static inline float comp(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

/* pbrt's gamma(n) in f32, as raytree's geometry::gamma. */
static float gamma_f(int n) {
    float nu = (float)n * (0x1p-23f * 0.5f);
    return nu / (1.0f - nu);
}

/* ---- scene, as written by benches/peer.rs ---- */
typedef struct {
    vec3 ambient, diffuse, specular;
    float shininess;
    vec3 reflectivity, transparency;
    float ior;
} Material;
typedef struct { vec3 position, color; } Light;
typedef struct { vec3 center; float radius; uint32_t material; } Sphere;

static struct {
    uint32_t width, height, max_depth, blinn;
    vec3 cam_pos, look_at, up;
    float fov_y_deg;
    vec3 background, ambient_light;
    uint32_t n_materials, n_lights, n_spheres, n_triangles;
    Material *materials;
    Light *lights;
    Sphere *spheres;
    float *vertices; /* 9 floats a triangle, plus padding Embree may read */
    uint32_t *tri_material;
} S;

static void die(const char *what) { fprintf(stderr, "embree_whitted: %s\n", what); exit(2); }

static void read_exact(FILE *f, void *dst, size_t bytes) {
    if (fread(dst, 1, bytes, f) != bytes) die("the scene file is truncated");
}
static uint32_t read_u32(FILE *f) { uint32_t v; read_exact(f, &v, 4); return v; }
static vec3 read_vec3(FILE *f) { float v[3]; read_exact(f, v, 12); return v3(v[0], v[1], v[2]); }
static float read_f32(FILE *f) { float v; read_exact(f, &v, 4); return v; }

static void *alloc(size_t bytes) {
    void *p = calloc(1, bytes ? bytes : 1);
    if (!p) die("out of memory");
    return p;
}

static void load_scene(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open the scene file");
    char magic[8];
    read_exact(f, magic, 8);
    if (memcmp(magic, "RTPEER01", 8) != 0) die("not a raytree peer scene (magic RTPEER01)");
    S.width = read_u32(f);
    S.height = read_u32(f);
    S.max_depth = read_u32(f);
    S.blinn = read_u32(f);
    S.cam_pos = read_vec3(f);
    S.look_at = read_vec3(f);
    S.up = read_vec3(f);
    S.fov_y_deg = read_f32(f);
    S.background = read_vec3(f);
    S.ambient_light = read_vec3(f);
    S.n_materials = read_u32(f);
    S.materials = alloc(sizeof(Material) * S.n_materials);
    for (uint32_t i = 0; i < S.n_materials; i++) {
        Material *m = &S.materials[i];
        m->ambient = read_vec3(f);
        m->diffuse = read_vec3(f);
        m->specular = read_vec3(f);
        m->shininess = read_f32(f);
        m->reflectivity = read_vec3(f);
        m->transparency = read_vec3(f);
        m->ior = read_f32(f);
    }
    S.n_lights = read_u32(f);
    S.lights = alloc(sizeof(Light) * S.n_lights);
    for (uint32_t i = 0; i < S.n_lights; i++) {
        S.lights[i].position = read_vec3(f);
        S.lights[i].color = read_vec3(f);
    }
    S.n_spheres = read_u32(f);
    S.spheres = alloc(sizeof(Sphere) * S.n_spheres);
    for (uint32_t i = 0; i < S.n_spheres; i++) {
        S.spheres[i].center = read_vec3(f);
        S.spheres[i].radius = read_f32(f);
        S.spheres[i].material = read_u32(f);
    }
    S.n_triangles = read_u32(f);
    S.vertices = alloc(sizeof(float) * (9 * (size_t)S.n_triangles + 4));
    read_exact(f, S.vertices, sizeof(float) * 9 * (size_t)S.n_triangles);
    S.tri_material = alloc(sizeof(uint32_t) * S.n_triangles);
    read_exact(f, S.tri_material, sizeof(uint32_t) * S.n_triangles);
    fclose(f);
}

/* ---- analytic spheres as an Embree user geometry (--spheres user) ----
 * A callback per sphere test, with raytree's own intersection (rows `user-high` and
 * `user-medium` of the bench).
 * Embree's built-in spheres (the default) solve t = projection -+ half-chord, whose near root
 * cancels for a ray that leaves a sphere; with raytree's error-bound origin offsets the bench
 * scene shows no re-hit (the same rays and pixels as raytree), which the bench checks. */

/* raytree's robust_roots + pick_root: nearest t in (tmin, tmax) or NAN. */
static float sphere_t(const Sphere *s, vec3 o, vec3 u, float tmin, float tmax) {
    vec3 f = sub(o, s->center);
    float a = dot(u, u);
    float bp = -dot(f, u);
    float r2 = s->radius * s->radius;
    vec3 l = add(f, scale(bp / a, u));
    float disc = r2 - dot(l, l);
    if (isnan(disc) || disc < 0.0f) return NAN;
    float c = dot(f, f) - r2;
    float q = bp + copysignf(sqrtf(a * disc), bp);
    float t0, t1;
    if (q == 0.0f) {
        t0 = t1 = 0.0f;
    } else {
        t0 = c / q;
        t1 = q / a;
        if (t0 > t1) { float t = t0; t0 = t1; t1 = t; }
    }
    if (t0 > tmin) return t0 < tmax ? t0 : NAN;
    if (t1 > tmin && t1 < tmax) return t1;
    return NAN;
}

static void sphere_bounds(const struct RTCBoundsFunctionArguments *args) {
    const Sphere *s = &((const Sphere *)args->geometryUserPtr)[args->primID];
    float pad = 4.0f * 0x1p-23f * (fabsf(s->center.x) + fabsf(s->center.y) + fabsf(s->center.z) + s->radius);
    float r = s->radius + pad;
    args->bounds_o->lower_x = s->center.x - r;
    args->bounds_o->lower_y = s->center.y - r;
    args->bounds_o->lower_z = s->center.z - r;
    args->bounds_o->upper_x = s->center.x + r;
    args->bounds_o->upper_y = s->center.y + r;
    args->bounds_o->upper_z = s->center.z + r;
}

/* Only rtcIntersect1/rtcOccluded1 are used, so N is 1. */
static void sphere_intersect(const struct RTCIntersectFunctionNArguments *args) {
    if (!args->valid[0]) return;
    struct RTCRayHit *rh = (struct RTCRayHit *)args->rayhit;
    const Sphere *s = &((const Sphere *)args->geometryUserPtr)[args->primID];
    vec3 o = v3(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z);
    vec3 d = v3(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z);
    float t = sphere_t(s, o, d, rh->ray.tnear, rh->ray.tfar);
    if (isnan(t)) return;
    rh->ray.tfar = t;
    rh->hit.u = rh->hit.v = 0.0f;
    rh->hit.Ng_x = rh->hit.Ng_y = rh->hit.Ng_z = 0.0f; /* the shader computes it */
    rh->hit.primID = args->primID;
    rh->hit.geomID = args->geomID;
    rh->hit.instID[0] = args->context->instID[0];
}

static void sphere_occluded(const struct RTCOccludedFunctionNArguments *args) {
    if (!args->valid[0]) return;
    struct RTCRay *ray = (struct RTCRay *)args->ray;
    const Sphere *s = &((const Sphere *)args->geometryUserPtr)[args->primID];
    vec3 o = v3(ray->org_x, ray->org_y, ray->org_z);
    vec3 d = v3(ray->dir_x, ray->dir_y, ray->dir_z);
    if (!isnan(sphere_t(s, o, d, ray->tnear, ray->tfar))) ray->tfar = -INFINITY;
}

/* ---- memory accounting ---- */
static _Atomic long long embree_bytes, embree_peak;
static bool memory_monitor(void *ptr, ssize_t bytes, bool post) {
    (void)ptr;
    (void)post;
    long long now = atomic_fetch_add(&embree_bytes, (long long)bytes) + bytes;
    long long peak = atomic_load(&embree_peak);
    while (now > peak && !atomic_compare_exchange_weak(&embree_peak, &peak, now)) {}
    return true;
}

static long peak_rss_kb(void) {
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long kb = -1;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "VmHWM:", 6) == 0) kb = strtol(line + 6, NULL, 10);
    fclose(f);
    return kb;
}

static double now_secs(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the Whitted trace, as raytree's src/trace/mod.rs ---- */
static RTCScene scene;
enum { GEOM_TRIANGLES = 0, GEOM_SPHERES = 1 };

typedef struct { uint64_t primary, reflected, refracted, shadow; } Counts;
typedef enum { PRIMARY, REFLECTED, REFRACTED } Kind;

/* pbrt-v4 OffsetRayOrigin (raytree's OffsetMethod::ErrorBound). */
static vec3 offset_origin(vec3 p, vec3 err, vec3 n, vec3 dir) {
    vec3 n_out = dot(dir, n) < 0.0f ? neg(n) : n;
    float d = dot(vabs(n), err);
    vec3 off = scale(d, n_out);
    vec3 po = add(p, off);
    float *c = &po.x, *o = &off.x;
    for (int i = 0; i < 3; i++) {
        if (o[i] > 0.0f) c[i] = nextafterf(c[i], INFINITY);
        else if (o[i] < 0.0f) c[i] = nextafterf(c[i], -INFINITY);
    }
    return po;
}

static vec3 reflect(vec3 u, vec3 n) { return sub(u, scale(2.0f * dot(u, n), n)); }

/* max(cos, 0)^shininess, cos of the halfway vector (Blinn-Phong) or of the mirrored light
 * (Phong), as raytree's shade::light_terms_with. */
static inline float highlight_cos(vec3 n, vec3 l, vec3 view) {
    if (S.blinn) { /* as raytree's shade::cos_halfway: N·(L + V) / |L + V| */
        vec3 s = add(l, view);
        float len = length(s);
        return (len > 0.0f && isfinite(len)) ? dot(n, s) / len : 0.0f;
    }
    return dot(reflect(neg(l), n), view);
}

/* x^shininess as raytree's shade::highlight_power, so both sides do the same shading work: a
 * whole-number shininess up to 1024 by repeated squaring in double, rounded to float once;
 * powf otherwise. */
static inline float highlight_power(float x, float shininess) {
    if (!(shininess >= 0.0f && shininess <= 1024.0f)) return powf(x, shininess);
    unsigned n = (unsigned)shininess;
    if ((float)n != shininess) return powf(x, shininess);
    double base = (double)x, power = 1.0;
    while (n > 0) {
        if (n & 1u) power *= base;
        base *= base;
        n >>= 1;
    }
    return (float)power;
}

static inline float highlight(vec3 n, vec3 l, vec3 view, float shininess) {
    return highlight_power(fmaxf(highlight_cos(n, l, view), 0.0f), shininess);
}

static int flush_denormals;

/* `x` (>= 0) rounded to the nearest float, subnormals included, in double arithmetic (which
 * flush-to-zero leaves alone at these magnitudes). */
static inline double to_float_grid(double x) {
    if (x >= (double)FLT_MIN) return (double)(float)x;
    return nearbyint(x * 0x1p149) * 0x1p-149;
}

/* Whether raytree, which keeps subnormals, finds the light's specular term not zero where this
 * thread's flush-to-zero made it zero: a highlight (or its product with ks) in the subnormal
 * range, as a shininess of 300 gives at cos < 0.75. raytree casts a shadow ray there (its rule:
 * no ray only where the term is exactly zero), so the harness does too, or the two would not
 * trace the same rays (the `glass` scene: 3 % of its shadow rays). Only asked where the
 * flushed term is zero. */
static int specular_survives_without_ftz(vec3 n, vec3 l, vec3 view, float shininess, vec3 ks) {
    if (!flush_denormals) return 0;
    double c = fmax((double)highlight_cos(n, l, view), 0.0);
    double spec = to_float_grid(pow(c, (double)shininess));
    return to_float_grid((double)ks.x * spec) != 0.0 || to_float_grid((double)ks.y * spec) != 0.0 ||
           to_float_grid((double)ks.z * spec) != 0.0;
}

static int refract(vec3 u, vec3 n, float eta, vec3 *out) {
    float cos_i = fminf(fmaxf(-dot(u, n), 0.0f), 1.0f);
    float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
    if (k < 0.0f) return 0;
    float cos_r = sqrtf(k);
    *out = normalize(sub(scale(eta, u), scale(cos_r - eta * cos_i, n)));
    return 1;
}

static vec3 trace(vec3 o, vec3 d, Kind kind, uint32_t depth, Counts *counts,
                  struct RTCIntersectContext *ctx) {
    if (depth > S.max_depth) return S.background;
    if (kind == PRIMARY) counts->primary++;
    else if (kind == REFLECTED) counts->reflected++;
    else counts->refracted++;

    struct RTCRayHit rh;
    rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = INFINITY;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return S.background;

    /* Hit point, its error bound and the geometric normal, as raytree's Tracer::surface. */
    vec3 p, err, n;
    const Material *m;
    if (rh.hit.geomID == GEOM_SPHERES) {
        const Sphere *s = &S.spheres[rh.hit.primID];
        float t = rh.ray.tfar;
        vec3 at = add(o, scale(t, d));
        double vx = (double)at.x - s->center.x, vy = (double)at.y - s->center.y,
               vz = (double)at.z - s->center.z;
        double len = sqrt(vx * vx + vy * vy + vz * vz);
        if (len > 0.0 && isfinite(len)) {
            double k = (double)s->radius / len;
            vx *= k; vy *= k; vz *= k;
        }
        p = v3((float)(s->center.x + vx), (float)(s->center.y + vy), (float)(s->center.z + vz));
        vec3 local = v3((float)vx, (float)vy, (float)vz);
        err = add(scale(gamma_f(5), vabs(local)), scale(gamma_f(1), vabs(p)));
        n = normalize(scale(1.0f / s->radius, sub(p, s->center)));
        m = &S.materials[s->material];
    } else {
        const float *v = &S.vertices[9 * (size_t)rh.hit.primID];
        vec3 a = v3(v[0], v[1], v[2]), b = v3(v[3], v[4], v[5]), c = v3(v[6], v[7], v[8]);
        float b1 = rh.hit.u, b2 = rh.hit.v, b0 = 1.0f - b1 - b2;
        vec3 w0 = scale(b0, a), w1 = scale(b1, b), w2 = scale(b2, c);
        p = add(add(w0, w1), w2);
        err = scale(gamma_f(7), add(add(vabs(w0), vabs(w1)), vabs(w2)));
        n = normalize(cross(sub(b, a), sub(c, a)));
        m = &S.materials[S.tri_material[rh.hit.primID]];
    }
    int front = dot(d, n) < 0.0f;
    if (!front) n = neg(n);
    vec3 view = neg(d);

    vec3 diffuse = v3(0, 0, 0), specular = v3(0, 0, 0);
    for (uint32_t i = 0; i < S.n_lights; i++) {
        const Light *light = &S.lights[i];
        vec3 to_light = sub(light->position, p);
        float dist = length(to_light);
        vec3 l = scale(1.0f / dist, to_light);
        float n_dot_l = dot(n, l);
        /* raytree's rule: no shadow ray where the light's unshadowed contribution is exactly
         * zero: the light behind the surface; or no diffuse in the light's channels and a
         * specular term of exactly zero (none in its channels, or a highlight that is 0: the
         * halfway vector beyond 90 degrees, or a power that underflows). A NaN term casts. */
        if (!(n_dot_l > 0.0f)) continue;
        vec3 ks = mul(light->color, m->specular);
        /* The highlight, formed before the shadow ray only where the rule needs it. */
        int have_spec = 0;
        float spec = 0.0f;
        if (is_zero(mul(light->color, m->diffuse))) {
            if (is_zero(ks)) continue;
            spec = highlight(n, l, view, m->shininess);
            have_spec = 1;
            if (is_zero(scale(spec, ks)) && !specular_survives_without_ftz(n, l, view, m->shininess, ks))
                continue;
        }
        vec3 origin = offset_origin(p, err, n, l);
        vec3 seg = sub(light->position, origin);
        float seg_len = length(seg);
        vec3 sd = scale(1.0f / seg_len, seg);
        counts->shadow++;
        struct RTCRay sr;
        sr.org_x = origin.x; sr.org_y = origin.y; sr.org_z = origin.z;
        sr.dir_x = sd.x; sr.dir_y = sd.y; sr.dir_z = sd.z;
        sr.tnear = 0.0f;
        sr.tfar = seg_len;
        sr.time = 0.0f;
        sr.mask = 0xffffffffu;
        sr.id = 0;
        sr.flags = 0;
        rtcOccluded1(scene, ctx, &sr);
        if (sr.tfar < 0.0f) continue; /* blocked */
        if (!have_spec) spec = highlight(n, l, view, m->shininess);
        diffuse = add(diffuse, scale(n_dot_l, mul(light->color, m->diffuse)));
        specular = add(specular, scale(spec, mul(light->color, m->specular)));
    }
    vec3 color = add(add(mul(m->ambient, S.ambient_light), diffuse), specular);

    vec3 kr = m->reflectivity, kt = m->transparency;
    vec3 refl_w = kr, tdir;
    int refracted = 0;
    if (!is_zero(kt)) {
        float eta = front ? 1.0f / m->ior : m->ior;
        refracted = refract(d, n, eta, &tdir);
        if (!refracted) refl_w = add(refl_w, kt); /* total internal reflection */
    }
    if (!is_zero(refl_w)) {
        vec3 r = normalize(reflect(d, n));
        vec3 c = trace(offset_origin(p, err, n, r), r, REFLECTED, depth + 1, counts, ctx);
        color = add(color, mul(refl_w, c));
    }
    if (refracted) {
        vec3 c = trace(offset_origin(p, err, n, tdir), tdir, REFRACTED, depth + 1, counts, ctx);
        color = add(color, mul(kt, c));
    }
    return color;
}

/* ---- camera (raytree's CameraFrame) and tiles ---- */
static vec3 cam_right, cam_up, cam_back;
static float tan_half, aspect;
static float *image;
enum { TILE = 32 };
static uint32_t tiles_x, tiles_y;
static atomic_uint next_tile;

typedef struct { Counts counts; } Worker;

static void *worker(void *arg) {
    Worker *w = arg;
    /* Rays are counted on this thread's stack and stored once at the end: the workers' counts
     * sit next to each other in one array, and incrementing them per ray from two threads
     * made the cache line ping-pong between the cores whenever the array's placement put both
     * in one line (Embree's frame then took 0.12 s instead of 0.07 s, in about one process in
     * three, as the heap's address fell). */
    Counts counts = {0};
    if (flush_denormals) {
        /* What Embree asks of every thread that traces (its verbose start-up warns without). */
#if defined(__SSE3__)
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#else
        die("--ftz 1 needs an SSE3 target");
#endif
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    float fw = (float)S.width, fh = (float)S.height;
    for (;;) {
        unsigned tile = atomic_fetch_add(&next_tile, 1);
        if (tile >= tiles_x * tiles_y) break;
        uint32_t x0 = (tile % tiles_x) * TILE, y0 = (tile / tiles_x) * TILE;
        for (uint32_t y = y0; y < y0 + TILE && y < S.height; y++) {
            for (uint32_t x = x0; x < x0 + TILE && x < S.width; x++) {
                float px = (float)x + 0.5f, py = (float)y + 0.5f;
                float cx = (2.0f * px / fw - 1.0f) * aspect * tan_half;
                float cy = (1.0f - 2.0f * py / fh) * tan_half;
                vec3 d = normalize(sub(add(scale(cx, cam_right), scale(cy, cam_up)), cam_back));
                vec3 c = trace(S.cam_pos, d, PRIMARY, 0, &counts, &ctx);
                float *out = &image[3 * ((size_t)y * S.width + x)];
                out[0] = c.x; out[1] = c.y; out[2] = c.z;
            }
        }
    }
    w->counts = counts;
    return NULL;
}

static void rtc_error(void *user, enum RTCError code, const char *str) {
    (void)user;
    fprintf(stderr, "embree_whitted: Embree error %d: %s\n", (int)code, str ? str : "");
    exit(2);
}

static const char *usage =
    "usage: embree_whitted [--spheres builtin|user] [--quality low|medium|high] [--frames K] "
    "[--ftz 0|1] [--robust 0|1] SCENE.bin THREADS [IMAGE.f32]";

/* One frame on `threads` pthreads: its render-phase seconds; its ray counts in `total`. */
static double render_frame(int threads, Worker *workers, pthread_t *ids, Counts *total) {
    memset(workers, 0, sizeof(Worker) * threads);
    atomic_store(&next_tile, 0);
    double start = now_secs();
    for (int i = 0; i < threads; i++)
        if (pthread_create(&ids[i], NULL, worker, &workers[i]) != 0) die("pthread_create failed");
    for (int i = 0; i < threads; i++) pthread_join(ids[i], NULL);
    double secs = now_secs() - start;
    memset(total, 0, sizeof *total);
    for (int i = 0; i < threads; i++) {
        total->primary += workers[i].counts.primary;
        total->reflected += workers[i].counts.reflected;
        total->refracted += workers[i].counts.refracted;
        total->shadow += workers[i].counts.shadow;
    }
    return secs;
}

int main(int argc, char **argv) {
    const char *spheres_name = "builtin", *quality_name = "high";
    int frames = 1, robust = 0;
    int argi = 1;
    while (argi < argc && strncmp(argv[argi], "--", 2) == 0) {
        if (argi + 1 >= argc) die(usage);
        if (strcmp(argv[argi], "--spheres") == 0) spheres_name = argv[argi + 1];
        else if (strcmp(argv[argi], "--quality") == 0) quality_name = argv[argi + 1];
        else if (strcmp(argv[argi], "--frames") == 0) frames = atoi(argv[argi + 1]);
        else if (strcmp(argv[argi], "--ftz") == 0) flush_denormals = atoi(argv[argi + 1]);
        else if (strcmp(argv[argi], "--robust") == 0) robust = atoi(argv[argi + 1]);
        else die(usage);
        argi += 2;
    }
    if (argc - argi < 2) die(usage);
    const char *scene_path = argv[argi], *image_path = argc - argi > 2 ? argv[argi + 2] : NULL;
    int threads = atoi(argv[argi + 1]);
    if (threads < 1 || threads > 256) die("THREADS must be 1..256");
    if (frames < 1 || frames > 1000) die("--frames must be 1..1000");
    int builtin_spheres;
    if (strcmp(spheres_name, "builtin") == 0) builtin_spheres = 1;
    else if (strcmp(spheres_name, "user") == 0) builtin_spheres = 0;
    else die("--spheres must be builtin or user");
    enum RTCBuildQuality quality;
    if (strcmp(quality_name, "low") == 0) quality = RTC_BUILD_QUALITY_LOW;
    else if (strcmp(quality_name, "medium") == 0) quality = RTC_BUILD_QUALITY_MEDIUM;
    else if (strcmp(quality_name, "high") == 0) quality = RTC_BUILD_QUALITY_HIGH;
    else die("--quality must be low, medium or high");

    double t0 = now_secs();
    load_scene(scene_path);
    char config[64];
    snprintf(config, sizeof config, "threads=%d", threads);
    RTCDevice device = rtcNewDevice(config);
    if (!device) die("rtcNewDevice failed");
    rtcSetDeviceErrorFunction(device, rtc_error, NULL);
    rtcSetDeviceMemoryMonitorFunction(device, memory_monitor, NULL);
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene, quality);

    uint32_t *indices = alloc(sizeof(uint32_t) * 3 * (size_t)S.n_triangles);
    for (uint32_t i = 0; i < 3 * S.n_triangles; i++) indices[i] = i;
    if (S.n_triangles > 0) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(g, quality);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, S.vertices, 0,
                                   12, 3 * (size_t)S.n_triangles);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices, 0, 12,
                                   S.n_triangles);
        rtcCommitGeometry(g);
        if (rtcAttachGeometry(scene, g) != GEOM_TRIANGLES) die("unexpected geometry id");
        rtcReleaseGeometry(g);
    }
    float *sphere_points = NULL;
    if (S.n_spheres > 0 && builtin_spheres) {
        /* Embree's own spheres: x, y, z, radius per point. */
        sphere_points = alloc(sizeof(float) * 4 * S.n_spheres);
        for (uint32_t i = 0; i < S.n_spheres; i++) {
            sphere_points[4 * i + 0] = S.spheres[i].center.x;
            sphere_points[4 * i + 1] = S.spheres[i].center.y;
            sphere_points[4 * i + 2] = S.spheres[i].center.z;
            sphere_points[4 * i + 3] = S.spheres[i].radius;
        }
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        rtcSetGeometryBuildQuality(g, quality);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, sphere_points,
                                   0, 16, S.n_spheres);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, GEOM_SPHERES);
        rtcReleaseGeometry(g);
    } else if (S.n_spheres > 0) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryBuildQuality(g, quality);
        rtcSetGeometryUserPrimitiveCount(g, S.n_spheres);
        rtcSetGeometryUserData(g, S.spheres);
        rtcSetGeometryBoundsFunction(g, sphere_bounds, NULL);
        rtcSetGeometryIntersectFunction(g, sphere_intersect);
        rtcSetGeometryOccludedFunction(g, sphere_occluded);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, GEOM_SPHERES);
        rtcReleaseGeometry(g);
    }
    double t1 = now_secs();
    rtcCommitScene(scene);
    double t2 = now_secs();

    cam_back = normalize(sub(S.cam_pos, S.look_at));
    cam_right = normalize(cross(S.up, cam_back));
    cam_up = cross(cam_back, cam_right);
    float deg_to_rad = 3.14159265358979323846f / 180.0f;
    tan_half = tanf(S.fov_y_deg * deg_to_rad * 0.5f);
    aspect = (float)S.width / (float)S.height;
    image = alloc(sizeof(float) * 3 * (size_t)S.width * S.height);
    tiles_x = (S.width + TILE - 1) / TILE;
    tiles_y = (S.height + TILE - 1) / TILE;

    Worker *workers = alloc(sizeof(Worker) * threads);
    pthread_t *ids = alloc(sizeof(pthread_t) * threads);
    double *frame_secs = alloc(sizeof(double) * frames);
    Counts total, first;
    for (int f = 0; f < frames; f++) {
        frame_secs[f] = render_frame(threads, workers, ids, &total);
        if (f == 0) first = total;
        else if (memcmp(&first, &total, sizeof total) != 0)
            die("a warm frame traced other rays than the first");
    }

    uint64_t rays = total.primary + total.reflected + total.refracted + total.shadow;
    printf("embree_version %d.%d.%d\n", RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH);
    printf("threads %d\n", threads);
    printf("spheres_geometry %s\n", builtin_spheres ? "builtin" : "user");
    printf("build_quality %s\n", quality_name);
    printf("flush_denormals %d\n", flush_denormals);
    printf("scene_robust %d\n", robust);
    printf("triangles %u\nspheres %u\n", S.n_triangles, S.n_spheres);
    printf("load_secs %.6f\nbuild_secs %.6f\nrender_secs %.6f\n", t1 - t0, t2 - t1, frame_secs[0]);
    printf("frame_secs");
    for (int f = 0; f < frames; f++) printf(" %.6f", frame_secs[f]);
    printf("\n");
    printf("primary %llu\nreflected %llu\nrefracted %llu\nshadow %llu\n",
           (unsigned long long)total.primary, (unsigned long long)total.reflected,
           (unsigned long long)total.refracted, (unsigned long long)total.shadow);
    printf("mrays_per_sec %.4f\n", (double)rays / frame_secs[0] / 1e6);
    printf("embree_peak_bytes %lld\n", (long long)atomic_load(&embree_peak));
    printf("geometry_bytes %llu\n",
           (unsigned long long)(S.n_triangles * (36ull + 12ull) +
                                S.n_spheres * (builtin_spheres ? 16ull : sizeof(Sphere))));
    printf("peak_rss_kb %ld\n", peak_rss_kb());

    if (image_path) {
        FILE *f = fopen(image_path, "wb");
        if (!f) die("cannot write the image");
        fwrite(image, sizeof(float), 3 * (size_t)S.width * S.height, f);
        fclose(f);
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}
