//! A hand-written CUDA sphere tracer of bench/handwritten/scene.sdf, the yardstick for sdfc's
//! own kernels (BENCHMARKS.md, "Beside a hand-written tracer"): the same primitives, camera,
//! light and settings, written as one would by hand — the field as inline functions, a camera
//! ray marched to d < ε·t (a negative distance counts as a hit, and in a shadow ray as blocked), the normal from four taps, one soft-shadow ray (res = min(res,
//! k·d/t)), Phong shading — and the whole image in one launch.
//!
//! Build: nvcc -O3 -arch=sm_90 -o tracer tracer.cu
//! Run:   ./tracer EPSILON [MAX_STEPS] [WIDTH HEIGHT] [FRAMES] [out.ppm]
//! Prints the median frame time (CUDA events) and the mean steps per pixel (camera and
//! shadow rays) as one line of JSON.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

// The field and the material index of the nearest surface (0 floor, 1 red, 2 blue).
__device__ inline float map(V p, int *m) {
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
__device__ inline float sdf(V p) { int m; return map(p, &m); }

__device__ inline float tol(float eps, float t, V p) {
  V a = vabs(p);
  return fmaxf(eps * t, 8.0f * 1.1920929e-7f * fmaxf(a.x, fmaxf(a.y, a.z)));
}

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
    float f = sdf(p);
    steps++;
    if (f < tol(P.eps, t, p)) { hit = true; break; }
    t += f;
    if (t > P.max_dist) break;
  }
  V colour = v(0, 0, 0);
  if (hit) {
    V p = P.eye + d * t;
    int m;
    map(p, &m);
    V a = vabs(p);
    float h = fmaxf(P.eps * t, 64.0f * 1.1920929e-7f * (1.0f + fmaxf(a.x, fmaxf(a.y, a.z))));
    V k0 = v(1, -1, -1), k1 = v(-1, -1, 1), k2 = v(-1, 1, -1), k3 = v(1, 1, 1);
    V g = k0 * sdf(p + k0 * h) + k1 * sdf(p + k1 * h) + k2 * sdf(p + k2 * h) + k3 * sdf(p + k3 * h);
    V n = norm(g);
    V c = m == 0 ? v(0.6f, 0.6f, 0.6f) : m == 1 ? v(0.8f, 0.25f, 0.2f) : v(0.2f, 0.35f, 0.8f);
    float ks = m == 0 ? 0.0f : 0.4f;
    // The soft shadow towards the directional light.
    V o = p + n * (4.0f * h);
    float res = 1.0f, s = 0.0f;
    for (int i = 0; i < P.max_steps; i++) {
      V q = o + P.light * s;
      float f = sdf(q);
      steps++;
      if (s > 0.0f) res = fminf(res, P.k * f / s);
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

int main(int argc, char **argv) {
  float eps = argc > 1 ? atof(argv[1]) : 1e-5f;
  int max_steps = argc > 2 ? atoi(argv[2]) : 512;
  int width = argc > 4 ? atoi(argv[3]) : 1920, height = argc > 4 ? atoi(argv[4]) : 1080;
  int frames = argc > 5 ? atoi(argv[5]) : 21;
  const char *ppm = argc > 6 ? argv[6] : nullptr;
  Params P;
  P.eye = v(0, 2.5f, -7);
  V look = v(0, 0.7f, 0);
  P.fwd = norm(look - P.eye);
  // Right-handed, +y up: u points to the picture's right (-x when looking along +z).
  P.u = norm(cross(P.fwd, v(0, 1, 0)));
  P.v = cross(P.u, P.fwd);
  float tan = tanf(50.0f * 3.14159265f / 360.0f);
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
    render<<<grid, block>>>(P, image, steps);
    cudaEventRecord(b);
    cudaEventSynchronize(b);
    cudaEventElapsedTime(&ms, a, b);
  }
  std::vector<float> times;
  for (int f = 0; f < frames; f++) {
    cudaEventRecord(a);
    render<<<grid, block>>>(P, image, steps);
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
  printf("{\"eps\": %g, \"max_steps\": %d, \"median_ms\": %.4f, \"min_ms\": %.4f, \"steps_per_pixel\": %.2f}\n",
         eps, max_steps, times[times.size() / 2], times[0], sum / n);
  return 0;
}
