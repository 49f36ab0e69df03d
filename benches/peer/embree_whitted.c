/* embree_whitted.c: the peer of raytree's peer benchmark (benches/peer.rs). A Whitted ray
 * tracer over Embree 3 that renders the scene `benches/peer.rs` hands it with the same camera,
 * materials, recursion, shadow-ray rule and ray-origin offsets as raytree's `src/trace/`, on N
 * pthreads over 32x32 tiles taken from an atomic counter, with single rays (rtcIntersect1,
 * rtcOccluded1), 8-wide packets (rtcIntersect8, rtcOccluded8) or streams (rtcIntersect1M,
 * rtcOccluded1M).
 *
 * Usage: embree_whitted [--spheres builtin|user] [--quality low|medium|high] [--frames K]
 *                       [--ftz 0|1] [--robust 0|1] [--camera single|packet|stream]
 *                       [--block WxH] [--secondary single|stream] SCENE.bin THREADS [IMAGE.f32]
 *
 * --camera single (the default) traces each pixel's tree depth first, ray by ray. `packet`
 *   traces a tile breadth first: its camera rays in 8-wide packets of a WxH pixel block
 *   (--block, default 4x2) and each light's shadow rays of a block as one packet; `stream`
 *   traces the tile's camera rays and their shadow rays as streams. --secondary then says how
 *   the reflected and refracted rays and their shadow rays go: `single` ray by ray, `stream`
 *   as one stream per generation of a tile.
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

/* The callbacks take N rays at once (N is 1 for rtcIntersect1/rtcOccluded1, the packet width
 * for rtcIntersect8 and for the packets Embree forms from a stream), laid out as RTCRayHitN:
 * field k of lane i at float k*N + i, the hit after the ray's 12*N floats. */
static void sphere_intersect(const struct RTCIntersectFunctionNArguments *args) {
    const unsigned n = args->N;
    float *r = (float *)args->rayhit;
    float *h = r + 12 * n;
    unsigned *hu = (unsigned *)h;
    const Sphere *s = &((const Sphere *)args->geometryUserPtr)[args->primID];
    for (unsigned i = 0; i < n; i++) {
        if (!args->valid[i]) continue;
        vec3 o = v3(r[0 * n + i], r[1 * n + i], r[2 * n + i]);
        vec3 d = v3(r[4 * n + i], r[5 * n + i], r[6 * n + i]);
        float t = sphere_t(s, o, d, r[3 * n + i], r[8 * n + i]);
        if (isnan(t)) continue;
        r[8 * n + i] = t;
        /* Ng, u and v are left 0: the shader computes the normal. */
        for (unsigned k = 0; k < 5; k++) h[k * n + i] = 0.0f;
        hu[5 * n + i] = args->primID;
        hu[6 * n + i] = args->geomID;
        hu[7 * n + i] = args->context->instID[0];
    }
}

static void sphere_occluded(const struct RTCOccludedFunctionNArguments *args) {
    const unsigned n = args->N;
    float *r = (float *)args->ray;
    const Sphere *s = &((const Sphere *)args->geometryUserPtr)[args->primID];
    for (unsigned i = 0; i < n; i++) {
        if (!args->valid[i]) continue;
        vec3 o = v3(r[0 * n + i], r[1 * n + i], r[2 * n + i]);
        vec3 d = v3(r[4 * n + i], r[5 * n + i], r[6 * n + i]);
        if (!isnan(sphere_t(s, o, d, r[3 * n + i], r[8 * n + i]))) r[8 * n + i] = -INFINITY;
    }
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

/* A hit surface, as raytree's Tracer::surface: the hit point, its error bound, the geometric
 * normal turned toward the ray, the material. */
typedef struct {
    vec3 p, err, n, view;
    const Material *m;
    int front;
} Surface;

static void surface_at(vec3 o, vec3 d, float t, unsigned geom, unsigned prim, float b1, float b2,
                       Surface *s) {
    vec3 n;
    if (geom == GEOM_SPHERES) {
        const Sphere *sp = &S.spheres[prim];
        vec3 at = add(o, scale(t, d));
        double vx = (double)at.x - sp->center.x, vy = (double)at.y - sp->center.y,
               vz = (double)at.z - sp->center.z;
        double len = sqrt(vx * vx + vy * vy + vz * vz);
        if (len > 0.0 && isfinite(len)) {
            double k = (double)sp->radius / len;
            vx *= k; vy *= k; vz *= k;
        }
        s->p = v3((float)(sp->center.x + vx), (float)(sp->center.y + vy), (float)(sp->center.z + vz));
        vec3 local = v3((float)vx, (float)vy, (float)vz);
        s->err = add(scale(gamma_f(5), vabs(local)), scale(gamma_f(1), vabs(s->p)));
        n = normalize(scale(1.0f / sp->radius, sub(s->p, sp->center)));
        s->m = &S.materials[sp->material];
    } else {
        const float *v = &S.vertices[9 * (size_t)prim];
        vec3 a = v3(v[0], v[1], v[2]), b = v3(v[3], v[4], v[5]), c = v3(v[6], v[7], v[8]);
        float b0 = 1.0f - b1 - b2;
        vec3 w0 = scale(b0, a), w1 = scale(b1, b), w2 = scale(b2, c);
        s->p = add(add(w0, w1), w2);
        s->err = scale(gamma_f(7), add(add(vabs(w0), vabs(w1)), vabs(w2)));
        n = normalize(cross(sub(b, a), sub(c, a)));
        s->m = &S.materials[S.tri_material[prim]];
    }
    s->front = dot(d, n) < 0.0f;
    s->n = s->front ? n : neg(n);
    s->view = neg(d);
}

/* One light seen from a surface: whether it needs a shadow ray and, if so, the ray. */
typedef struct {
    vec3 l, origin, dir;
    float n_dot_l, length, spec;
    int have_spec;
} LightQuery;

/* raytree's rule: no shadow ray where the light's unshadowed contribution is exactly zero: the
 * light behind the surface; or no diffuse in the light's channels and a specular term of
 * exactly zero (none in its channels, or a highlight that is 0: the halfway vector beyond 90
 * degrees, or a power that underflows). A NaN term casts. */
static int light_query(const Surface *s, const Light *light, LightQuery *q) {
    vec3 to_light = sub(light->position, s->p);
    float dist = length(to_light);
    q->l = scale(1.0f / dist, to_light);
    q->n_dot_l = dot(s->n, q->l);
    if (!(q->n_dot_l > 0.0f)) return 0;
    const Material *m = s->m;
    vec3 ks = mul(light->color, m->specular);
    /* The highlight, formed before the shadow ray only where the rule needs it. */
    q->have_spec = 0;
    q->spec = 0.0f;
    if (is_zero(mul(light->color, m->diffuse))) {
        if (is_zero(ks)) return 0;
        q->spec = highlight(s->n, q->l, s->view, m->shininess);
        q->have_spec = 1;
        if (is_zero(scale(q->spec, ks)) &&
            !specular_survives_without_ftz(s->n, q->l, s->view, m->shininess, ks))
            return 0;
    }
    q->origin = offset_origin(s->p, s->err, s->n, q->l);
    vec3 seg = sub(light->position, q->origin);
    q->length = length(seg);
    q->dir = scale(1.0f / q->length, seg);
    return 1;
}

/* The unblocked light's diffuse and specular terms, added in the light's order. */
static void light_add(const Surface *s, const Light *light, LightQuery *q, vec3 *diffuse,
                      vec3 *specular) {
    if (!q->have_spec) q->spec = highlight(s->n, q->l, s->view, s->m->shininess);
    *diffuse = add(*diffuse, scale(q->n_dot_l, mul(light->color, s->m->diffuse)));
    *specular = add(*specular, scale(q->spec, mul(light->color, s->m->specular)));
}

static vec3 local_colour(const Surface *s, vec3 diffuse, vec3 specular) {
    return add(add(mul(s->m->ambient, S.ambient_light), diffuse), specular);
}

/* The secondary rays a surface spawns: a reflected one with weight refl_w (kr, plus kt on total
 * internal reflection) and a refracted one with weight kt. */
typedef struct {
    vec3 refl_w, kt, r_org, r_dir, t_org, t_dir;
    int reflects, refracts;
} Children;

static void children_of(const Surface *s, vec3 d, Children *c) {
    const Material *m = s->m;
    c->kt = m->transparency;
    c->refl_w = m->reflectivity;
    c->refracts = 0;
    if (!is_zero(c->kt)) {
        float eta = s->front ? 1.0f / m->ior : m->ior;
        c->refracts = refract(d, s->n, eta, &c->t_dir);
        if (!c->refracts) c->refl_w = add(c->refl_w, c->kt); /* total internal reflection */
    }
    c->reflects = !is_zero(c->refl_w);
    if (c->reflects) {
        c->r_dir = normalize(reflect(d, s->n));
        c->r_org = offset_origin(s->p, s->err, s->n, c->r_dir);
    }
    if (c->refracts) c->t_org = offset_origin(s->p, s->err, s->n, c->t_dir);
}

static void init_ray(struct RTCRay *r, vec3 o, vec3 d, float tfar) {
    r->org_x = o.x; r->org_y = o.y; r->org_z = o.z;
    r->dir_x = d.x; r->dir_y = d.y; r->dir_z = d.z;
    r->tnear = 0.0f;
    r->tfar = tfar;
    r->time = 0.0f;
    r->mask = 0xffffffffu;
    r->id = 0;
    r->flags = 0;
}

static void init_rayhit(struct RTCRayHit *rh, vec3 o, vec3 d) {
    init_ray(&rh->ray, o, d, INFINITY);
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* The single-ray Whitted recursion, as raytree's src/trace/mod.rs. */
static vec3 trace(vec3 o, vec3 d, Kind kind, uint32_t depth, Counts *counts,
                  struct RTCIntersectContext *ctx) {
    if (depth > S.max_depth) return S.background;
    if (kind == PRIMARY) counts->primary++;
    else if (kind == REFLECTED) counts->reflected++;
    else counts->refracted++;

    struct RTCRayHit rh;
    init_rayhit(&rh, o, d);
    rtcIntersect1(scene, ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return S.background;

    Surface s;
    surface_at(o, d, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, &s);
    vec3 diffuse = v3(0, 0, 0), specular = v3(0, 0, 0);
    for (uint32_t i = 0; i < S.n_lights; i++) {
        LightQuery q;
        if (!light_query(&s, &S.lights[i], &q)) continue;
        counts->shadow++;
        struct RTCRay sr;
        init_ray(&sr, q.origin, q.dir, q.length);
        rtcOccluded1(scene, ctx, &sr);
        if (sr.tfar < 0.0f) continue; /* blocked */
        light_add(&s, &S.lights[i], &q, &diffuse, &specular);
    }
    vec3 color = local_colour(&s, diffuse, specular);

    Children c;
    children_of(&s, d, &c);
    if (c.reflects) color = add(color, mul(c.refl_w, trace(c.r_org, c.r_dir, REFLECTED, depth + 1, counts, ctx)));
    if (c.refracts) color = add(color, mul(c.kt, trace(c.t_org, c.t_dir, REFRACTED, depth + 1, counts, ctx)));
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

/* The camera ray's direction through pixel (x, y)'s centre. */
static vec3 camera_dir(uint32_t x, uint32_t y) {
    float fw = (float)S.width, fh = (float)S.height;
    float px = (float)x + 0.5f, py = (float)y + 0.5f;
    float cx = (2.0f * px / fw - 1.0f) * aspect * tan_half;
    float cy = (1.0f - 2.0f * py / fh) * tan_half;
    return normalize(sub(add(scale(cx, cam_right), scale(cy, cam_up)), cam_back));
}

/* What Embree asks of every thread that traces (its verbose start-up warns without). */
static void set_thread_ftz(void) {
    if (!flush_denormals) return;
#if defined(__SSE3__)
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#else
    die("--ftz 1 needs an SSE3 target");
#endif
}

static void *worker(void *arg) {
    Worker *w = arg;
    /* Rays are counted on this thread's stack and stored once at the end: the workers' counts
     * sit next to each other in one array, and incrementing them per ray from two threads
     * made the cache line ping-pong between the cores whenever the array's placement put both
     * in one line (Embree's frame then took 0.12 s instead of 0.07 s, in about one process in
     * three, as the heap's address fell). */
    Counts counts = {0};
    set_thread_ftz();
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (;;) {
        unsigned tile = atomic_fetch_add(&next_tile, 1);
        if (tile >= tiles_x * tiles_y) break;
        uint32_t x0 = (tile % tiles_x) * TILE, y0 = (tile / tiles_x) * TILE;
        for (uint32_t y = y0; y < y0 + TILE && y < S.height; y++) {
            for (uint32_t x = x0; x < x0 + TILE && x < S.width; x++) {
                vec3 c = trace(S.cam_pos, camera_dir(x, y), PRIMARY, 0, &counts, &ctx);
                float *out = &image[3 * ((size_t)y * S.width + x)];
                out[0] = c.x; out[1] = c.y; out[2] = c.z;
            }
        }
    }
    w->counts = counts;
    return NULL;
}

/* ---- the same trace over packets and streams (--camera packet|stream) ----
 * A tile is traced breadth-first, one generation of rays at a time: generation 0 the tile's
 * camera rays, generation g the reflected and refracted rays of generation g-1. Each generation
 * is intersected, its surfaces shaded up to their shadow rays, the shadow rays traced, and the
 * lights and the next generation's rays formed; at the end each ray's colour is composed from
 * its children's, deepest generation first, in the recursion's order of operations, so the
 * image is the single-ray one's.
 * - camera `packet`: generation 0 in BLOCK_W x BLOCK_H pixel blocks of 8 lanes, rtcIntersect8,
 *   and each light's shadow rays of a block as one rtcOccluded8 (coherent context);
 * - camera `stream`: generation 0 as one rtcIntersect1M stream of the tile's camera rays and
 *   its shadow rays as one rtcOccluded1M stream (coherent context);
 * - secondary `single`: later generations ray by ray (rtcIntersect1, rtcOccluded1);
 * - secondary `stream`: each later generation and its shadow rays as rtcIntersect1M and
 *   rtcOccluded1M streams (incoherent context). */
enum { CAMERA_SINGLE, CAMERA_PACKET, CAMERA_STREAM };
enum { SECONDARY_SINGLE, SECONDARY_STREAM };
static int camera_mode = CAMERA_SINGLE, secondary_mode = SECONDARY_SINGLE;
static uint32_t block_w = 4, block_h = 2;

typedef struct {
    vec3 o, d;
    int32_t pixel; /* generation 0: the pixel, -1 for a lane off the image; later: 0 */
    uint32_t depth;
    unsigned geom, prim;
    float t, u, v;
    vec3 local, refl_w, kt, color;
    int32_t child[2]; /* the reflected and refracted ray in the next generation; -1: none traced */
    uint8_t reflects, refracts;
} WRay;

typedef struct { void *p; size_t bytes; } Buf;

/* At least `bytes` (and at least one byte) of b, its contents not kept when it grows. */
static void *reserve(Buf *b, size_t bytes) {
    if (bytes == 0) bytes = 1;
    if (bytes > b->bytes || !b->p) {
        free(b->p);
        size_t want = ((2 * bytes + 63) / 64) * 64;
        b->p = aligned_alloc(64, want);
        if (!b->p) die("out of memory");
        b->bytes = want;
    }
    return b->p;
}

typedef struct {
    Buf gen_buf[64];
    size_t gen_n[64];
    Buf surf, query, cast, rh, sr, map;
    struct RTCIntersectContext coherent, incoherent;
    Counts counts;
} Wave;

static WRay *gen_rays(Wave *w, uint32_t g) { return (WRay *)w->gen_buf[g].p; }

static int lane_live(const WRay *r) { return r->pixel >= 0; }

/* Lane j of an 8-wide packet: a ray from o along d up to tfar. */
static void set_lane8(struct RTCRay8 *r, int j, vec3 o, vec3 d, float tfar) {
    r->org_x[j] = o.x; r->org_y[j] = o.y; r->org_z[j] = o.z;
    r->dir_x[j] = d.x; r->dir_y[j] = d.y; r->dir_z[j] = d.z;
    r->tnear[j] = 0.0f;
    r->tfar[j] = tfar;
    r->time[j] = 0.0f;
    r->mask[j] = 0xffffffffu;
    r->id[j] = 0;
    r->flags[j] = 0;
}

/* Whether generation g goes as streams (otherwise ray by ray, or as packets for generation 0). */
static int streamed(uint32_t g) {
    return g == 0 ? camera_mode == CAMERA_STREAM : secondary_mode == SECONDARY_STREAM;
}

/* Intersects generation g. */
static void wave_intersect(Wave *w, uint32_t g) {
    WRay *rays = gen_rays(w, g);
    size_t n = w->gen_n[g];
    if (g == 0 && camera_mode == CAMERA_PACKET) {
        for (size_t b = 0; b < n; b += 8) {
            struct RTCRayHit8 rh;
            int valid[8];
            for (int j = 0; j < 8; j++) {
                const WRay *r = &rays[b + j];
                valid[j] = lane_live(r) ? -1 : 0;
                set_lane8(&rh.ray, j, r->o, r->d, INFINITY);
                rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect8(valid, scene, &w->coherent, &rh);
            for (int j = 0; j < 8; j++) {
                WRay *r = &rays[b + j];
                r->geom = rh.hit.geomID[j];
                r->prim = rh.hit.primID[j];
                r->t = rh.ray.tfar[j];
                r->u = rh.hit.u[j];
                r->v = rh.hit.v[j];
            }
        }
        return;
    }
    struct RTCRayHit *rh = reserve(&w->rh, sizeof(struct RTCRayHit) * n);
    uint32_t *map = reserve(&w->map, sizeof(uint32_t) * n);
    unsigned m = 0;
    for (size_t i = 0; i < n; i++) {
        if (!lane_live(&rays[i])) continue;
        init_rayhit(&rh[m], rays[i].o, rays[i].d);
        map[m++] = (uint32_t)i;
    }
    int stream = streamed(g);
    struct RTCIntersectContext *ctx = g == 0 ? &w->coherent : &w->incoherent;
    if (stream) rtcIntersect1M(scene, ctx, rh, m, sizeof(struct RTCRayHit));
    else
        for (unsigned k = 0; k < m; k++) rtcIntersect1(scene, ctx, &rh[k]);
    for (unsigned k = 0; k < m; k++) {
        WRay *r = &rays[map[k]];
        r->geom = rh[k].hit.geomID;
        r->prim = rh[k].hit.primID;
        r->t = rh[k].ray.tfar;
        r->u = rh[k].hit.u;
        r->v = rh[k].hit.v;
    }
}

/* Traces generation g's shadow rays; a blocked one's cast flag becomes 0. */
static void wave_shadows(Wave *w, uint32_t g, const LightQuery *q, uint8_t *cast) {
    WRay *rays = gen_rays(w, g);
    size_t n = w->gen_n[g];
    const uint32_t lights = S.n_lights;
    if (g == 0 && camera_mode == CAMERA_PACKET) {
        for (size_t b = 0; b < n; b += 8) {
            for (uint32_t k = 0; k < lights; k++) {
                struct RTCRay8 sr;
                int valid[8], any = 0;
                for (int j = 0; j < 8; j++) {
                    size_t i = b + (size_t)j;
                    int live = lane_live(&rays[i]) && cast[i * lights + k];
                    valid[j] = live ? -1 : 0;
                    any |= live;
                    const LightQuery *lq = &q[i * lights + k];
                    vec3 o = live ? lq->origin : v3(0, 0, 0), d = live ? lq->dir : v3(0, 0, 1);
                    set_lane8(&sr, j, o, d, live ? lq->length : 0.0f);
                }
                if (!any) continue;
                rtcOccluded8(valid, scene, &w->coherent, &sr);
                for (int j = 0; j < 8; j++)
                    if (valid[j] && sr.tfar[j] < 0.0f) cast[(b + (size_t)j) * lights + k] = 0;
            }
        }
        return;
    }
    size_t most = n * lights;
    struct RTCRay *sr = reserve(&w->sr, sizeof(struct RTCRay) * most);
    uint32_t *map = reserve(&w->map, sizeof(uint32_t) * most);
    unsigned m = 0;
    for (size_t i = 0; i < n * lights; i++) {
        if (!cast[i]) continue;
        init_ray(&sr[m], q[i].origin, q[i].dir, q[i].length);
        map[m++] = (uint32_t)i;
    }
    int stream = streamed(g);
    struct RTCIntersectContext *ctx = g == 0 ? &w->coherent : &w->incoherent;
    if (stream) rtcOccluded1M(scene, ctx, sr, m, sizeof(struct RTCRay));
    else
        for (unsigned k = 0; k < m; k++) rtcOccluded1(scene, ctx, &sr[k]);
    for (unsigned k = 0; k < m; k++)
        if (sr[k].tfar < 0.0f) cast[map[k]] = 0;
}

/* Appends a secondary ray to generation g; its index, or -1 beyond the depth limit (where the
 * recursion returns the background without tracing). */
static int32_t wave_push(Wave *w, uint32_t g, vec3 o, vec3 d, Kind kind) {
    if (g > S.max_depth) return -1;
    if (kind == REFLECTED) w->counts.reflected++;
    else w->counts.refracted++;
    WRay *r = &gen_rays(w, g)[w->gen_n[g]];
    memset(r, 0, sizeof *r);
    r->o = o;
    r->d = d;
    r->depth = g;
    return (int32_t)w->gen_n[g]++;
}

/* Shades generation g and forms generation g + 1. */
static void wave_shade(Wave *w, uint32_t g) {
    WRay *rays = gen_rays(w, g);
    size_t n = w->gen_n[g];
    const uint32_t lights = S.n_lights;
    Surface *surf = reserve(&w->surf, sizeof(Surface) * n);
    LightQuery *q = reserve(&w->query, sizeof(LightQuery) * n * lights);
    uint8_t *cast = reserve(&w->cast, n * lights);
    for (size_t i = 0; i < n; i++) {
        WRay *r = &rays[i];
        for (uint32_t k = 0; k < lights; k++) cast[i * lights + k] = 0;
        if (!lane_live(r) || r->geom == RTC_INVALID_GEOMETRY_ID) continue;
        surface_at(r->o, r->d, r->t, r->geom, r->prim, r->u, r->v, &surf[i]);
        for (uint32_t k = 0; k < lights; k++) {
            cast[i * lights + k] = (uint8_t)light_query(&surf[i], &S.lights[k], &q[i * lights + k]);
            w->counts.shadow += cast[i * lights + k];
        }
    }
    wave_shadows(w, g, q, cast);
    if (g + 1 < 64) {
        reserve(&w->gen_buf[g + 1], sizeof(WRay) * 2 * n);
        w->gen_n[g + 1] = 0;
    }
    for (size_t i = 0; i < n; i++) {
        WRay *r = &rays[i];
        r->child[0] = r->child[1] = -1;
        r->reflects = r->refracts = 0;
        if (!lane_live(r)) continue;
        if (r->geom == RTC_INVALID_GEOMETRY_ID) {
            r->local = S.background;
            continue;
        }
        const Surface *s = &surf[i];
        vec3 diffuse = v3(0, 0, 0), specular = v3(0, 0, 0);
        for (uint32_t k = 0; k < lights; k++)
            if (cast[i * lights + k]) light_add(s, &S.lights[k], &q[i * lights + k], &diffuse, &specular);
        r->local = local_colour(s, diffuse, specular);
        Children c;
        children_of(s, r->d, &c);
        r->refl_w = c.refl_w;
        r->kt = c.kt;
        r->reflects = (uint8_t)c.reflects;
        r->refracts = (uint8_t)c.refracts;
        if (c.reflects) r->child[0] = wave_push(w, g + 1, c.r_org, c.r_dir, REFLECTED);
        if (c.refracts) r->child[1] = wave_push(w, g + 1, c.t_org, c.t_dir, REFRACTED);
    }
}

static void *worker_wave(void *arg) {
    Worker *out = arg;
    set_thread_ftz();
    if (S.max_depth >= 63) die("--camera packet|stream traces at most 62 levels below the camera");
    Wave *w = alloc(sizeof(Wave));
    rtcInitIntersectContext(&w->coherent);
    w->coherent.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcInitIntersectContext(&w->incoherent);
    const uint32_t blocks_x = (TILE + block_w - 1) / block_w, blocks_y = (TILE + block_h - 1) / block_h;
    for (;;) {
        unsigned tile = atomic_fetch_add(&next_tile, 1);
        if (tile >= tiles_x * tiles_y) break;
        uint32_t x0 = (tile % tiles_x) * TILE, y0 = (tile / tiles_x) * TILE;
        /* Generation 0: the tile's camera rays, block by block, 8 lanes each. */
        WRay *cam = reserve(&w->gen_buf[0], sizeof(WRay) * 8 * blocks_x * blocks_y);
        size_t n = 0;
        for (uint32_t by = 0; by < blocks_y; by++)
            for (uint32_t bx = 0; bx < blocks_x; bx++)
                for (uint32_t j = 0; j < 8; j++) {
                    uint32_t x = x0 + bx * block_w + j % block_w, y = y0 + by * block_h + j / block_w;
                    WRay *r = &cam[n++];
                    memset(r, 0, sizeof *r);
                    int inside = x < x0 + TILE && y < y0 + TILE && x < S.width && y < S.height;
                    r->pixel = inside ? (int32_t)(y * S.width + x) : -1;
                    if (!inside) continue;
                    r->o = S.cam_pos;
                    r->d = camera_dir(x, y);
                    w->counts.primary++;
                }
        w->gen_n[0] = n;
        uint32_t gens = 0;
        for (uint32_t g = 0; g <= S.max_depth && w->gen_n[g] > 0; g++) {
            wave_intersect(w, g);
            wave_shade(w, g);
            gens = g + 1;
        }
        /* Colours, deepest generation first: local, then + refl_w x reflected, + kt x refracted. */
        for (uint32_t g = gens; g-- > 0;) {
            WRay *rays = gen_rays(w, g);
            const WRay *next = g + 1 < gens ? gen_rays(w, g + 1) : NULL;
            for (size_t i = 0; i < w->gen_n[g]; i++) {
                WRay *r = &rays[i];
                if (!lane_live(r)) continue;
                vec3 color = r->local;
                if (r->reflects)
                    color = add(color, mul(r->refl_w, r->child[0] >= 0 ? next[r->child[0]].color : S.background));
                if (r->refracts)
                    color = add(color, mul(r->kt, r->child[1] >= 0 ? next[r->child[1]].color : S.background));
                r->color = color;
            }
        }
        WRay *rays = gen_rays(w, 0);
        for (size_t i = 0; i < w->gen_n[0]; i++) {
            if (!lane_live(&rays[i])) continue;
            float *px = &image[3 * (size_t)rays[i].pixel];
            px[0] = rays[i].color.x; px[1] = rays[i].color.y; px[2] = rays[i].color.z;
        }
    }
    out->counts = w->counts;
    for (int g = 0; g < 64; g++) free(w->gen_buf[g].p);
    free(w->surf.p); free(w->query.p); free(w->cast.p); free(w->rh.p); free(w->sr.p); free(w->map.p);
    free(w);
    return NULL;
}

static void rtc_error(void *user, enum RTCError code, const char *str) {
    (void)user;
    fprintf(stderr, "embree_whitted: Embree error %d: %s\n", (int)code, str ? str : "");
    exit(2);
}

static const char *usage =
    "usage: embree_whitted [--spheres builtin|user] [--quality low|medium|high] [--frames K] "
    "[--ftz 0|1] [--robust 0|1] [--camera single|packet|stream] [--block WxH] "
    "[--secondary single|stream] SCENE.bin THREADS [IMAGE.f32]";

/* One frame on `threads` pthreads: its render-phase seconds; its ray counts in `total`. */
static double render_frame(int threads, Worker *workers, pthread_t *ids, Counts *total) {
    memset(workers, 0, sizeof(Worker) * threads);
    atomic_store(&next_tile, 0);
    double start = now_secs();
    for (int i = 0; i < threads; i++)
        if (pthread_create(&ids[i], NULL, camera_mode == CAMERA_SINGLE ? worker : worker_wave,
                           &workers[i]) != 0)
            die("pthread_create failed");
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
    const char *camera_name = "single", *secondary_name = "single", *block_name = "4x2";
    int frames = 1, robust = 0;
    int argi = 1;
    while (argi < argc && strncmp(argv[argi], "--", 2) == 0) {
        if (argi + 1 >= argc) die(usage);
        if (strcmp(argv[argi], "--spheres") == 0) spheres_name = argv[argi + 1];
        else if (strcmp(argv[argi], "--quality") == 0) quality_name = argv[argi + 1];
        else if (strcmp(argv[argi], "--frames") == 0) frames = atoi(argv[argi + 1]);
        else if (strcmp(argv[argi], "--ftz") == 0) flush_denormals = atoi(argv[argi + 1]);
        else if (strcmp(argv[argi], "--robust") == 0) robust = atoi(argv[argi + 1]);
        else if (strcmp(argv[argi], "--camera") == 0) camera_name = argv[argi + 1];
        else if (strcmp(argv[argi], "--secondary") == 0) secondary_name = argv[argi + 1];
        else if (strcmp(argv[argi], "--block") == 0) block_name = argv[argi + 1];
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

    if (strcmp(camera_name, "single") == 0) camera_mode = CAMERA_SINGLE;
    else if (strcmp(camera_name, "packet") == 0) camera_mode = CAMERA_PACKET;
    else if (strcmp(camera_name, "stream") == 0) camera_mode = CAMERA_STREAM;
    else die("--camera must be single, packet or stream");
    if (strcmp(secondary_name, "single") == 0) secondary_mode = SECONDARY_SINGLE;
    else if (strcmp(secondary_name, "stream") == 0) secondary_mode = SECONDARY_STREAM;
    else die("--secondary must be single or stream");
    if (sscanf(block_name, "%ux%u", &block_w, &block_h) != 2 || block_w * block_h != 8 ||
        TILE % block_w != 0 || TILE % block_h != 0)
        die("--block must be WxH with W x H = 8 (8x1, 4x2, 2x4 or 1x8)");
    if (camera_mode == CAMERA_SINGLE && secondary_mode != SECONDARY_SINGLE)
        die("--secondary stream needs --camera packet or stream");

    double t0 = now_secs();
    load_scene(scene_path);
    char config[64];
    snprintf(config, sizeof config, "threads=%d", threads);
    RTCDevice device = rtcNewDevice(config);
    if (!device) die("rtcNewDevice failed");
    rtcSetDeviceErrorFunction(device, rtc_error, NULL);
    rtcSetDeviceMemoryMonitorFunction(device, memory_monitor, NULL);
    /* A build without packet or stream support refuses those calls at run time; say so first. */
    long native8 = (long)rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED);
    long streams = (long)rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED);
    if (camera_mode == CAMERA_PACKET && !native8)
        die("this Embree build has no 8-wide packets (RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED is 0)");
    if ((camera_mode == CAMERA_STREAM || secondary_mode == SECONDARY_STREAM) && !streams)
        die("this Embree build has no ray streams (RTC_DEVICE_PROPERTY_RAY_STREAM_SUPPORTED is 0)");
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
    printf("native_ray8 %ld\nray_streams %ld\n", native8, streams);
    printf("camera_rays %s\n", camera_name);
    printf("camera_block %s\n", camera_mode == CAMERA_PACKET ? block_name : "-");
    printf("secondary_rays %s\n", secondary_name);
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
