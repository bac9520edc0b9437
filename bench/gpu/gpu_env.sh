# Sourced by the GPU scripts (run_gpu.sh, run_scale.sh) with their arguments, [--small]
# FREDHOLM OUTDIR: sets $small, $target (a bundle from make_bundle.sh, or a fredholm binary),
# $out and $log (OUTDIR/log.txt, emptied); then probes the machine into
# $out/probe.txt, points the OpenCL ICD loader at NVIDIA's driver where no vendors file names
# it, and defines `fredholm` (the command, as an array) and `fh LIMIT ARGS...`, which runs
# it with a time limit and logs the command and its output to $log.
small=0
if [ "${1:-}" = "--small" ]; then small=1; shift; fi
if [ $# -ne 2 ]; then
  echo "usage: $0 [--small] FREDHOLM_BUNDLE_OR_BINARY OUTDIR" >&2
  exit 2
fi
target=$1
out=$2
mkdir -p "$out" || exit 2
log="$out/log.txt"
: >"$log"

# ---- The machine ------------------------------------------------------------------------
{
  echo "== uname"; uname -a
  echo "== os"; head -4 /etc/os-release 2>/dev/null
  echo "== glibc"; ldd --version 2>/dev/null | head -1
  echo "== cpus"; nproc
  echo "== nvidia-smi"; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>&1 || true
  echo "== OpenCL ICD files"; ls -l /etc/OpenCL/vendors 2>&1 || true
} >"$out/probe.txt" 2>&1

# NVIDIA's OpenCL driver, for an ICD loader that has no vendors file naming it.
find_nvidia_opencl() {
  local d
  for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib \
           /usr/local/cuda/lib64 /usr/local/cuda/compat /usr/local/cuda/targets/x86_64-linux/lib; do
    [ -e "$d/libnvidia-opencl.so.1" ] && { echo "$d/libnvidia-opencl.so.1"; return; }
  done
  ldconfig -p 2>/dev/null | awk '/libnvidia-opencl.so.1/ {print $NF; exit}'
}
nvidia_opencl=$(find_nvidia_opencl)
vendors="$out/icd-vendors"
rm -rf "$vendors"
mkdir -p "$vendors"
cp /etc/OpenCL/vendors/*.icd "$vendors/" 2>/dev/null
if [ -n "$nvidia_opencl" ] && ! grep -qs nvidia "$vendors"/*.icd; then
  echo "$nvidia_opencl" >"$vendors/nvidia-found.icd"
fi
export OCL_ICD_VENDORS="$vendors"
echo "nvidia_opencl=${nvidia_opencl:-none}" >>"$out/probe.txt"

# ---- How to run fredholm ----------------------------------------------------------------
if [ -d "$target" ]; then
  libpath="$target/lib"
  [ -n "$nvidia_opencl" ] && libpath="$libpath:$(dirname "$nvidia_opencl")"
  fredholm=("$target/lib/ld-linux-x86-64.so.2" --library-path "$libpath" "$target/bin/fredholm")
  [ -d "$target/scenes" ] && export FREDHOLM_SCENES="$target/scenes"
  cpu_reference="$target/reference/cornell-mis.pfm"
else
  fredholm=("$target")
  cpu_reference=""
fi
export FREDHOLM_CACHE_DIR="$out/program-cache"

# Runs fredholm with a time limit, logging the command and its output; returns its status.
fh() {
  local limit=$1
  shift
  echo "\$ fredholm $*" >>"$log"
  timeout "$limit" "${fredholm[@]}" "$@" >>"$log" 2>&1
  local rc=$?
  echo "(exit $rc)" >>"$log"
  return $rc
}

