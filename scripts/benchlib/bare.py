#!/usr/bin/env python3
"""A bare driver context in a process of its own, no sdfc: the floor under a whole render's
device opening (the first-second suite runs `bare.py cuda|vulkan` and reads the seconds it
prints): CUDA's cuInit and cuCtxCreate, or Vulkan's instance, physical devices and a device
with one queue, through ctypes."""

import ctypes
import sys
import time


def bare_cuda():
    """Seconds to load libcuda, initialise it and create a context on device 0."""
    t = time.perf_counter()
    cu = ctypes.CDLL("libcuda.so.1")
    assert cu.cuInit(0) == 0, "cuInit"
    dev = ctypes.c_int()
    assert cu.cuDeviceGet(ctypes.byref(dev), 0) == 0, "cuDeviceGet"
    ctx = ctypes.c_void_p()
    assert cu.cuCtxCreate_v2(ctypes.byref(ctx), 0, dev) == 0, "cuCtxCreate"
    assert cu.cuCtxSynchronize() == 0, "cuCtxSynchronize"
    return time.perf_counter() - t


def bare_vulkan():
    """Seconds to load the Vulkan loader, create an instance, enumerate the physical devices
    and create a device with one queue on the first (the floor under wgpu's device)."""
    t = time.perf_counter()
    vk = ctypes.CDLL("libvulkan.so.1")
    P, U32 = ctypes.c_void_p, ctypes.c_uint32

    class InstanceInfo(ctypes.Structure):
        _fields_ = [("sType", ctypes.c_int), ("pNext", P), ("flags", U32), ("app", P),
                    ("layers", U32), ("layer_names", P), ("exts", U32), ("ext_names", P)]

    class QueueInfo(ctypes.Structure):
        _fields_ = [("sType", ctypes.c_int), ("pNext", P), ("flags", U32), ("family", U32),
                    ("count", U32), ("priorities", ctypes.POINTER(ctypes.c_float))]

    class DeviceInfo(ctypes.Structure):
        _fields_ = [("sType", ctypes.c_int), ("pNext", P), ("flags", U32), ("queues", U32),
                    ("queue_infos", ctypes.POINTER(QueueInfo)), ("layers", U32),
                    ("layer_names", P), ("exts", U32), ("ext_names", P), ("features", P)]

    instance = P()
    info = InstanceInfo(sType=1)  # VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO
    assert vk.vkCreateInstance(ctypes.byref(info), None, ctypes.byref(instance)) == 0
    n = U32()
    vk.vkEnumeratePhysicalDevices(instance, ctypes.byref(n), None)
    devices = (P * n.value)()
    assert vk.vkEnumeratePhysicalDevices(instance, ctypes.byref(n), devices) == 0
    assert n.value > 0, "no physical device"
    priority = ctypes.c_float(1.0)
    queue = QueueInfo(sType=2, family=0, count=1, priorities=ctypes.pointer(priority))
    dinfo = DeviceInfo(sType=3, queues=1, queue_infos=ctypes.pointer(queue))
    device = P()
    assert vk.vkCreateDevice(P(devices[0]), ctypes.byref(dinfo), None, ctypes.byref(device)) == 0
    return time.perf_counter() - t


if __name__ == "__main__":
    print("%.6f" % (bare_cuda() if sys.argv[1] == "cuda" else bare_vulkan()))
