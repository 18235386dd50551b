//! A hand-written CUDA sphere tracer of three scenes, the yardstick for sdfc's own kernels
//! (BENCHMARKS.md, "Beside a hand-written tracer"): `spheres` (bench/handwritten/scene.sdf),
//! `bulb` (bulb.sdf, a Mandelbulb over a floor) and `lattice` (lattice.sdf, a repeated strut
//! lattice cut by a box), each with the same primitives, camera, light and settings as its
//! `.sdf` file, written as one would by hand — the field as inline functions (the Mandelbulb
//! in spherical coordinates with acos, atan2 and pow, leaving its loop once it escapes; the
//! lattice by folding the point into one cell), a camera ray marched to d < ε·t (a negative
//! distance counts as a hit, and in a shadow ray as blocked), the normal from four taps, one
//! shadow ray (soft: res = min(res, k·d/t); hard: blocked or not), Phong shading — and the
//! whole image in one launch.
//!
//! Build: nvcc -O3 -arch=sm_90 -o tracer tracer.cu
//! Run:   ./tracer SCENE soft|hard EPSILON [MAX_STEPS] [WIDTH HEIGHT] [FRAMES] [out.ppm]
//! Prints the median frame time (CUDA events) and the mean steps per pixel (camera and
//! shadow rays) as one line of JSON.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

struct V { float x, y, z; };
__host__ __device__ inline V v(float x, float y, float z) { return {x, y, z}; }
__host__ __device__ inline V operator+(V a, V b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
__host__ __device__ inline V operator-(V a, V b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
__host__ __device__ inline V operator*(V a, float s) { return {a.x * s, a.y * s, a.z * s}; }
__host__ __device__ inline float dot(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
__host__ __device__ inline float len(V a) { return sqrtf(dot(a, a)); }
__host__ __device__ inline V norm(V a) { return a * (1.0f / len(a)); }
__host__ __device__ inline V cross(V a, V b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
__device__ inline V vmax(V a, float m) { return {fmaxf(a.x, m), fmaxf(a.y, m), fmaxf(a.z, m)}; }
__device__ inline V vabs(V a) { return {fabsf(a.x), fabsf(a.y), fabsf(a.z)}; }

struct Params {
  V eye, fwd, u, v;
  float tan_x, tan_y;
  int width, height, max_steps;
  float eps, max_dist, k;
  V light;  // towards the light
};

__device__ inline float sphere(V p, V c, float r) { return len(p - c) - r; }
__device__ inline float box(V p, V c, V h, float r) {
  V q = vabs(p - c) - h;
  return len(vmax(q, 0.0f)) + fminf(fmaxf(q.x, fmaxf(q.y, q.z)), 0.0f) - r;
}
__device__ inline float torus(V p, V c, float R, float r) {
  V q = p - c;
  float a = sqrtf(q.x * q.x + q.z * q.z) - R;
  return sqrtf(a * a + q.y * q.y) - r;
}

enum Scene { SPHERES, BULB, LATTICE };

// The fields and the material index of the nearest surface (0 floor, 1 red, 2 blue).
__device__ inline float spheres(V p, int *m) {
  float d = p.y;
  int mat = 0;
  float e;
  e = sphere(p, v(-2, 0.7f, 0), 0.7f);       if (e < d) { d = e; mat = 1; }
  e = sphere(p, v(2.2f, 0.5f, 1), 0.5f);     if (e < d) { d = e; mat = 2; }
  e = sphere(p, v(0.3f, 0.35f, -1.6f), 0.35f); if (e < d) { d = e; mat = 2; }
  // round_box((0.6, 0.6, 0.6), 0.1): the rounding lies inside the half-extents.
  e = box(p, v(0.5f, 0.6f, 1.5f), v(0.5f, 0.5f, 0.5f), 0.1f); if (e < d) { d = e; mat = 1; }
  e = torus(p, v(-0.4f, 0.25f, -0.2f), 0.8f, 0.25f); if (e < d) { d = e; mat = 2; }
  e = box(p, v(1.6f, 1.6f, -0.3f), v(1.2f, 0.02f, 0.8f), 0.0f); if (e < d) { d = e; mat = 1; }
  *m = mat;
  return d;
}

// mandelbulb(8, 8): z <- z^8 + p in spherical coordinates (y up), bailout 2, the estimate
// 0.5 ln(r) r / dr, and |p| - 2 beyond |p| > 4.
__device__ inline float mandelbulb(V p) {
  float r0 = len(p);
  if (r0 > 4.0f) return r0 - 2.0f;
  V z = p;
  float dr = 1.0f;
  for (int i = 0; i < 8; i++) {
    float r = len(z);
    if (r > 2.0f) break;
    float theta = acosf(fminf(fmaxf(z.y / fmaxf(r, 1e-30f), -1.0f), 1.0f)) * 8.0f;
    float phi = atan2f(z.z, z.x) * 8.0f;
    dr = 8.0f * powf(r, 7.0f) * dr + 1.0f;
    float rn = powf(r, 8.0f);
    float st = sinf(theta);
    z = v(st * cosf(phi), cosf(theta), st * sinf(phi)) * rn + p;
  }
  float r = fmaxf(len(z), 1e-30f);
  return 0.5f * logf(r) * r / dr;
}

__device__ inline float bulb(V p, int *m) {
  float d = p.y + 1.3f;
  int mat = 0;
  float e = mandelbulb(p);
  if (e < d) { d = e; mat = 1; }
  *m = mat;
  return d;
}

// Square struts 0.1 thick along x, y and z every 0.5 (the point folded into its cell, the
// three struts through its centre), cut to the box of half-extents (1.5, 1, 1.5) about
// (0, 1.1, 0).
__device__ inline float lattice(V p, int *m) {
  float d = p.y;
  int mat = 0;
  V q = v(p.x - 0.5f * roundf(p.x * 2.0f), p.y - 0.5f * roundf(p.y * 2.0f),
          p.z - 0.5f * roundf(p.z * 2.0f));
  V o = v(0, 0, 0);
  float s = fminf(box(q, o, v(0.25f, 0.05f, 0.05f), 0.0f),
                  fminf(box(q, o, v(0.05f, 0.25f, 0.05f), 0.0f), box(q, o, v(0.05f, 0.05f, 0.25f), 0.0f)));
  float e = fmaxf(s, box(p, v(0, 1.1f, 0), v(1.5f, 1, 1.5f), 0.0f));
  if (e < d) { d = e; mat = 2; }
  *m = mat;
  return d;
}

template <int S> __device__ inline float map(V p, int *m) {
  return S == SPHERES ? spheres(p, m) : S == BULB ? bulb(p, m) : lattice(p, m);
}
template <int S> __device__ inline float sdf(V p) { int m; return map<S>(p, &m); }

__device__ inline float tol(float eps, float t, V p) {
  V a = vabs(p);
  return fmaxf(eps * t, 8.0f * 1.1920929e-7f * fmaxf(a.x, fmaxf(a.y, a.z)));
}

template <int S, bool SOFT>
__global__ void render(Params P, float4 *image, unsigned *steps_out) {
  int x = blockIdx.x * blockDim.x + threadIdx.x;
  int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= P.width || y >= P.height) return;
  float bx = 2.0f * ((x + 0.5f) / P.width) - 1.0f;
  float by = 1.0f - 2.0f * ((y + 0.5f) / P.height);
  V d = norm(P.fwd + P.u * (bx * P.tan_x) + P.v * (by * P.tan_y));
  unsigned steps = 0;
  float t = 0.0f;
  bool hit = false;
  for (int i = 0; i < P.max_steps; i++) {
    V p = P.eye + d * t;
    float f = sdf<S>(p);
    steps++;
    if (f < tol(P.eps, t, p)) { hit = true; break; }
    t += f;
    if (t > P.max_dist) break;
  }
  V colour = v(0, 0, 0);
  if (hit) {
    V p = P.eye + d * t;
    int m;
    map<S>(p, &m);
    V a = vabs(p);
    float h = fmaxf(P.eps * t, 64.0f * 1.1920929e-7f * (1.0f + fmaxf(a.x, fmaxf(a.y, a.z))));
    V k0 = v(1, -1, -1), k1 = v(-1, -1, 1), k2 = v(-1, 1, -1), k3 = v(1, 1, 1);
    V g = k0 * sdf<S>(p + k0 * h) + k1 * sdf<S>(p + k1 * h) + k2 * sdf<S>(p + k2 * h) +
            k3 * sdf<S>(p + k3 * h);
    V n = norm(g);
    V c = m == 0 ? v(0.6f, 0.6f, 0.6f) : m == 1 ? v(0.8f, 0.25f, 0.2f) : v(0.2f, 0.35f, 0.8f);
    float ks = m == 0 ? 0.0f : 0.4f;
    // The shadow towards the directional light.
    V o = p + n * (4.0f * h);
    float res = 1.0f, s = 0.0f;
    for (int i = 0; i < P.max_steps; i++) {
      V q = o + P.light * s;
      float f = sdf<S>(q);
      steps++;
      if (SOFT && s > 0.0f) res = fminf(res, P.k * f / s);
      if (f < tol(P.eps, t + s, q)) { res = 0.0f; break; }
      s += f;
      if (s >= P.max_dist) break;
    }
    res = fminf(fmaxf(res, 0.0f), 1.0f);
    float nl = fmaxf(dot(n, P.light), 0.0f);
    V r = n * (2.0f * dot(n, P.light)) - P.light;
    float spec = ks * powf(fmaxf(-dot(r, d), 0.0f), 32.0f);
    colour = c * 0.1f + (c * (0.9f * nl) + v(spec, spec, spec)) * res;
  }
  image[y * P.width + x] = make_float4(colour.x, colour.y, colour.z, 1.0f);
  steps_out[y * P.width + x] = steps;
}

// The launch of one scene and shadow kind.
typedef void (*Kernel)(Params, float4 *, unsigned *);
static Kernel kernel(int scene, bool soft) {
  static const Kernel k[3][2] = {{render<SPHERES, false>, render<SPHERES, true>},
                                 {render<BULB, false>, render<BULB, true>},
                                 {render<LATTICE, false>, render<LATTICE, true>}};
  return k[scene][soft];
}

int main(int argc, char **argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: tracer spheres|bulb|lattice soft|hard EPSILON [MAX_STEPS] [WIDTH HEIGHT] [FRAMES] [out.ppm]\n");
    return 2;
  }
  const char *names[3] = {"spheres", "bulb", "lattice"};
  int scene = -1;
  for (int i = 0; i < 3; i++) if (!strcmp(argv[1], names[i])) scene = i;
  bool soft = !strcmp(argv[2], "soft");
  if (scene < 0 || (!soft && strcmp(argv[2], "hard"))) {
    fprintf(stderr, "tracer: unknown scene or shadow kind: %s %s\n", argv[1], argv[2]);
    return 2;
  }
  float eps = atof(argv[3]);
  int max_steps = argc > 4 ? atoi(argv[4]) : 512;
  int width = argc > 6 ? atoi(argv[5]) : 1920, height = argc > 6 ? atoi(argv[6]) : 1080;
  int frames = argc > 7 ? atoi(argv[7]) : 21;
  const char *ppm = argc > 8 ? argv[8] : nullptr;
  // Each scene's camera, as its .sdf file places it (fov is vertical).
  const V eyes[3] = {v(0, 2.5f, -7), v(0, 1.2f, -3.4f), v(0, 3.5f, -6)};
  const V looks[3] = {v(0, 0.7f, 0), v(0, -0.1f, 0), v(0, 1, 0)};
  const float fovs[3] = {50, 45, 50};
  Kernel render_one = kernel(scene, soft);
  Params P;
  P.eye = eyes[scene];
  V look = looks[scene];
  P.fwd = norm(look - P.eye);
  // Right-handed, +y up: u points to the picture's right (-x when looking along +z).
  P.u = norm(cross(P.fwd, v(0, 1, 0)));
  P.v = cross(P.u, P.fwd);
  float tan = tanf(fovs[scene] * 3.14159265f / 360.0f);
  P.tan_y = tan;
  P.tan_x = tan * width / height;
  P.width = width; P.height = height; P.max_steps = max_steps;
  P.eps = eps; P.max_dist = 60.0f; P.k = 1.0f / tanf(4.0f * 3.14159265f / 180.0f);
  P.light = norm(v(0.5f, 1, -0.4f));
  size_t n = (size_t)width * height;
  float4 *image; unsigned *steps;
  cudaMalloc(&image, n * sizeof(float4));
  cudaMalloc(&steps, n * sizeof(unsigned));
  dim3 block(16, 16), grid((width + 15) / 16, (height + 15) / 16);
  cudaEvent_t a, b;
  cudaEventCreate(&a); cudaEventCreate(&b);
  // Warm-up: half a second of frames, so that the clocks have risen before timing.
  cudaEventRecord(a);
  for (float ms = 0.0f; ms < 500.0f;) {
    render_one<<<grid, block>>>(P, image, steps);
    cudaEventRecord(b);
    cudaEventSynchronize(b);
    cudaEventElapsedTime(&ms, a, b);
  }
  std::vector<float> times;
  for (int f = 0; f < frames; f++) {
    cudaEventRecord(a);
    render_one<<<grid, block>>>(P, image, steps);
    cudaEventRecord(b);
    cudaEventSynchronize(b);
    float ms; cudaEventElapsedTime(&ms, a, b);
    times.push_back(ms);
  }
  if (cudaGetLastError() != cudaSuccess) { fprintf(stderr, "CUDA error\n"); return 1; }
  std::sort(times.begin(), times.end());
  std::vector<unsigned> hs(n);
  cudaMemcpy(hs.data(), steps, n * sizeof(unsigned), cudaMemcpyDeviceToHost);
  double sum = 0; for (unsigned s : hs) sum += s;
  if (ppm) {
    std::vector<float4> img(n);
    cudaMemcpy(img.data(), image, n * sizeof(float4), cudaMemcpyDeviceToHost);
    FILE *f = fopen(ppm, "wb");
    fprintf(f, "P6\n%d %d\n255\n", width, height);
    for (size_t i = 0; i < n; i++) {
      float c[3] = {img[i].x, img[i].y, img[i].z};
      for (float ch : c) {
        float s = ch <= 0.0031308f ? 12.92f * ch : 1.055f * powf(ch, 1 / 2.4f) - 0.055f;
        fputc((int)(fminf(fmaxf(s, 0.0f), 1.0f) * 255.0f + 0.5f), f);
      }
    }
    fclose(f);
  }
  printf("{\"scene\": \"%s\", \"shadow\": \"%s\", \"eps\": %g, \"max_steps\": %d, \"median_ms\": %.4f, \"min_ms\": %.4f, \"steps_per_pixel\": %.2f}\n",
         argv[1], argv[2], eps, max_steps, times[times.size() / 2], times[0], sum / n);
  return 0;
}
