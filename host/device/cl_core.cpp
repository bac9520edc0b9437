// Error names and the checked helpers behind FH_CL.
#include "device/cl_core.h"

#include <sstream>

namespace fh {

const char* clErrorName(cl_int code) {
  switch (code) {
#define FH_NAME(c) \
  case c:          \
    return #c;
    FH_NAME(CL_SUCCESS)
    FH_NAME(CL_DEVICE_NOT_FOUND)
    FH_NAME(CL_DEVICE_NOT_AVAILABLE)
    FH_NAME(CL_COMPILER_NOT_AVAILABLE)
    FH_NAME(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    FH_NAME(CL_OUT_OF_RESOURCES)
    FH_NAME(CL_OUT_OF_HOST_MEMORY)
    FH_NAME(CL_PROFILING_INFO_NOT_AVAILABLE)
    FH_NAME(CL_MEM_COPY_OVERLAP)
    FH_NAME(CL_IMAGE_FORMAT_MISMATCH)
    FH_NAME(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    FH_NAME(CL_BUILD_PROGRAM_FAILURE)
    FH_NAME(CL_MAP_FAILURE)
    FH_NAME(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    FH_NAME(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    FH_NAME(CL_COMPILE_PROGRAM_FAILURE)
    FH_NAME(CL_LINKER_NOT_AVAILABLE)
    FH_NAME(CL_LINK_PROGRAM_FAILURE)
    FH_NAME(CL_DEVICE_PARTITION_FAILED)
    FH_NAME(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    FH_NAME(CL_INVALID_VALUE)
    FH_NAME(CL_INVALID_DEVICE_TYPE)
    FH_NAME(CL_INVALID_PLATFORM)
    FH_NAME(CL_INVALID_DEVICE)
    FH_NAME(CL_INVALID_CONTEXT)
    FH_NAME(CL_INVALID_QUEUE_PROPERTIES)
    FH_NAME(CL_INVALID_COMMAND_QUEUE)
    FH_NAME(CL_INVALID_HOST_PTR)
    FH_NAME(CL_INVALID_MEM_OBJECT)
    FH_NAME(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    FH_NAME(CL_INVALID_IMAGE_SIZE)
    FH_NAME(CL_INVALID_SAMPLER)
    FH_NAME(CL_INVALID_BINARY)
    FH_NAME(CL_INVALID_BUILD_OPTIONS)
    FH_NAME(CL_INVALID_PROGRAM)
    FH_NAME(CL_INVALID_PROGRAM_EXECUTABLE)
    FH_NAME(CL_INVALID_KERNEL_NAME)
    FH_NAME(CL_INVALID_KERNEL_DEFINITION)
    FH_NAME(CL_INVALID_KERNEL)
    FH_NAME(CL_INVALID_ARG_INDEX)
    FH_NAME(CL_INVALID_ARG_VALUE)
    FH_NAME(CL_INVALID_ARG_SIZE)
    FH_NAME(CL_INVALID_KERNEL_ARGS)
    FH_NAME(CL_INVALID_WORK_DIMENSION)
    FH_NAME(CL_INVALID_WORK_GROUP_SIZE)
    FH_NAME(CL_INVALID_WORK_ITEM_SIZE)
    FH_NAME(CL_INVALID_GLOBAL_OFFSET)
    FH_NAME(CL_INVALID_EVENT_WAIT_LIST)
    FH_NAME(CL_INVALID_EVENT)
    FH_NAME(CL_INVALID_OPERATION)
    FH_NAME(CL_INVALID_GL_OBJECT)
    FH_NAME(CL_INVALID_BUFFER_SIZE)
    FH_NAME(CL_INVALID_MIP_LEVEL)
    FH_NAME(CL_INVALID_GLOBAL_WORK_SIZE)
    FH_NAME(CL_INVALID_PROPERTY)
    FH_NAME(CL_INVALID_IMAGE_DESCRIPTOR)
    FH_NAME(CL_INVALID_COMPILER_OPTIONS)
    FH_NAME(CL_INVALID_LINKER_OPTIONS)
    FH_NAME(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef FH_NAME
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default:
      return "unknown OpenCL error";
  }
}

bool isOutOfMemory(cl_int code) {
  return code == CL_MEM_OBJECT_ALLOCATION_FAILURE || code == CL_OUT_OF_RESOURCES ||
         code == CL_OUT_OF_HOST_MEMORY || code == CL_INVALID_BUFFER_SIZE;
}

void throwClError(cl_int code, const char* call, const char* file, int line) {
  std::ostringstream msg;
  if (code == -1001) {
    msg << "no OpenCL platform found (is an ICD such as pocl-opencl-icd installed?)";
  } else {
    if (isOutOfMemory(code)) msg << "device out of memory: ";
    msg << call << " failed with " << clErrorName(code) << " (" << code << ") at " << file
        << ":" << line;
  }
  throw ClError(msg.str(), code);
}

cl::Buffer allocateBuffer(const cl::Context& context, const cl::Device& device,
                          cl_mem_flags flags, size_t bytes, const char* what,
                          const void* host) {
  // Zero-sized buffers are invalid in OpenCL; keep one element so kernels get a valid handle.
  if (bytes == 0) bytes = 16;
  const cl_ulong maxAlloc = device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  if (bytes > maxAlloc) {
    std::ostringstream msg;
    msg << "device out of memory: " << what << " needs " << bytes / (1 << 20)
        << " MiB, more than the device's largest allocation (" << maxAlloc / (1 << 20)
        << " MiB)";
    throw ClError(msg.str(), CL_MEM_OBJECT_ALLOCATION_FAILURE);
  }
  cl_int err = CL_SUCCESS;
  if (host) flags |= CL_MEM_COPY_HOST_PTR;
  cl::Buffer buffer(context, flags, bytes, const_cast<void*>(host), &err);
  if (err != CL_SUCCESS) {
    std::ostringstream msg;
    msg << "allocating " << what << " (" << bytes << " bytes)";
    throwClError(err, msg.str().c_str(), __FILE__, __LINE__);
  }
  return buffer;
}

}  // namespace fh
