# Sourced by the scripts that run on the GPU machine (the `device` tool): makes $OUT and the
# image folder, installs the Vulkan loader and the GL vendor-neutral libraries (libvulkan1,
# libglvnd0, libglx0, libegl1, libgl1, libgles2, libopengl0: Debian .debs) from .gl/, points Vulkan at the NVIDIA driver, sets
# the CUDA JIT cache (SDFC_CACHE_DIR, unless set), sets B to the sdfc binary carried in .dev/, and records the GPU and the
# date in $OUT/gpu.txt.
OUT=${OUT:-/tmp/out}
mkdir -p "$OUT" /tmp/sdfc-img
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
if [ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
fi
export SDFC_CACHE_DIR=${SDFC_CACHE_DIR:-/tmp/sdfc-jit}
B=./.dev/sdfc
chmod +x "$B"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv,noheader | tee "$OUT/gpu.txt"
date -u '+%Y-%m-%d %H:%M UTC' | tee -a "$OUT/gpu.txt"
