"""The time a process takes to open CUDA and do nothing else, through the driver API (ctypes,
standard library only): the floor under `sdfc render --backend cuda`'s first picture
(BENCHMARKS.md, "The first second"). Run it with /usr/bin/time for the whole process:

    /usr/bin/time -f "%e s" python3 bench/cuda_context.py
"""
import ctypes, time, sys
t0 = time.perf_counter()
cu = ctypes.CDLL("libcuda.so.1")
def ok(r, what):
    if r != 0: sys.exit("%s: %d" % (what, r))
ok(cu.cuInit(0), "init"); t1 = time.perf_counter()
dev = ctypes.c_int(); ok(cu.cuDeviceGet(ctypes.byref(dev), 0), "dev")
ctx = ctypes.c_void_p(); ok(cu.cuDevicePrimaryCtxRetain(ctypes.byref(ctx), dev), "retain"); ok(cu.cuCtxSetCurrent(ctx), "cur"); t2 = time.perf_counter()
n = 1920 * 1080 * 4
d = ctypes.c_uint64(); ok(cu.cuMemAlloc_v2(ctypes.byref(d), ctypes.c_size_t(n)), "alloc"); t3 = time.perf_counter()
ok(cu.cuMemsetD8_v2(d, ctypes.c_ubyte(7), ctypes.c_size_t(n)), "memset"); ok(cu.cuCtxSynchronize(), "sync"); t4 = time.perf_counter()
pageable = ctypes.create_string_buffer(n); t5 = time.perf_counter()
ok(cu.cuMemcpyDtoH_v2(pageable, d, ctypes.c_size_t(n)), "dtoh pageable"); t6 = time.perf_counter()
ok(cu.cuMemcpyDtoH_v2(pageable, d, ctypes.c_size_t(n)), "dtoh pageable 2"); t7 = time.perf_counter()
h = ctypes.c_void_p(); ok(cu.cuMemHostAlloc(ctypes.byref(h), ctypes.c_size_t(n), 0), "hostalloc"); t8 = time.perf_counter()
ok(cu.cuMemcpyDtoH_v2(h, d, ctypes.c_size_t(n)), "dtoh pinned"); t9 = time.perf_counter()
ctypes.memmove(pageable, h, n); t10 = time.perf_counter()
ms = lambda a, b: "%.1f" % ((b - a) * 1e3)
print("load+init", ms(t0, t1), "primary ctx", ms(t1, t2), "cuMemAlloc", ms(t2, t3), "memset+sync", ms(t3, t4), "host buffer", ms(t4, t5),
      "dtoh pageable", ms(t5, t6), "again", ms(t6, t7), "cuMemHostAlloc", ms(t7, t8), "dtoh pinned", ms(t8, t9), "memmove", ms(t9, t10))
sys.stdout.flush()
