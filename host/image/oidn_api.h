// The part of Intel Open Image Denoise's C API (version 2) that --denoise calls, declared
// here because Debian packages no OIDN headers: the library is loaded at run time
// (image/denoiser.h). Types and values as OIDN's API documentation gives them.
#pragma once
#include <cstddef>

namespace fh::oidn {

using Device = struct DeviceImpl*;
using Filter = struct FilterImpl*;

enum DeviceType : int { kDeviceTypeCpu = 1 };
enum Error : int { kErrorNone = 0 };
enum Format : int { kFormatFloat3 = 3 };

// The functions, by their exported names.
struct Api {
  Device (*newDevice)(int type);
  void (*commitDevice)(Device);
  int (*getDeviceError)(Device, const char** message);
  int (*getDeviceInt)(Device, const char* name);
  void (*releaseDevice)(Device);
  Filter (*newFilter)(Device, const char* type);
  void (*setSharedFilterImage)(Filter, const char* name, void* data, int format, size_t width, size_t height,
                               size_t byteOffset, size_t pixelByteStride, size_t rowByteStride);
  void (*setFilterBool)(Filter, const char* name, bool value);
  void (*commitFilter)(Filter);
  void (*executeFilter)(Filter);
  void (*releaseFilter)(Filter);
};

// Each member with the symbol it is loaded from.
#define FH_OIDN_FUNCTIONS(X)                                                                          \
  X(newDevice, "oidnNewDevice")                                                                       \
  X(commitDevice, "oidnCommitDevice")                                                                 \
  X(getDeviceError, "oidnGetDeviceError")                                                             \
  X(getDeviceInt, "oidnGetDeviceInt")                                                                 \
  X(releaseDevice, "oidnReleaseDevice")                                                               \
  X(newFilter, "oidnNewFilter")                                                                       \
  X(setSharedFilterImage, "oidnSetSharedFilterImage")                                                 \
  X(setFilterBool, "oidnSetFilterBool")                                                               \
  X(commitFilter, "oidnCommitFilter")                                                                 \
  X(executeFilter, "oidnExecuteFilter")                                                               \
  X(releaseFilter, "oidnReleaseFilter")

}  // namespace fh::oidn
