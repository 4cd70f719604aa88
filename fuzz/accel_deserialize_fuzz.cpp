// libFuzzer target: serialized acceleration structure data (src/accel/serialize.cpp), as
// vkCmdCopyMemoryToAccelerationStructureKHR and vkCopyMemoryToAccelerationStructureKHR hand it over from the
// application. Any input must be refused with an error or give a structure, never crash or read out of bounds.
// A top level is given no bottom levels, one, and 64 (null entries, as for inactive instances).
//
// Seeds: with VKRT_FUZZ_SEEDS=<folder> set, the target first writes a serialized bottom level of triangles, one of
// boxes and a top level with one instance of each there (fuzz/corpus/accel_deserialize holds them).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.hpp"

namespace {

void writeSeed(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  using namespace vkrt::accel;
  const char* dir = std::getenv("VKRT_FUZZ_SEEDS");
  if (!dir) return 0;
  std::string error;
  Geometry tri;
  tri.triangles.vertices = {0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
  tri.triangles.indices = {0, 1, 2, 2, 1, 3};
  Geometry box;
  box.kind = Geometry::Aabbs;
  box.aabbs.boxes = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
  std::shared_ptr<const Blas> a = Blas::build({tri}, {}, &error);
  std::shared_ptr<const Blas> b = Blas::build({box}, {}, &error);
  if (!a || !b) return 0;
  writeSeed(std::string(dir) + "/blas-triangles", serialize(*a));
  writeSeed(std::string(dir) + "/blas-boxes", serialize(*b));
  Instance ia, ib;
  ia.blas = a.get();
  ib.blas = b.get();
  ia.transform[0][0] = ia.transform[1][1] = ia.transform[2][2] = 1;
  ib.transform[0][0] = ib.transform[1][1] = ib.transform[2][2] = 1;
  std::shared_ptr<const Tlas> t = Tlas::build({ia, ib}, {}, &error);
  if (!t) return 0;
  std::vector<const Blas*> refs;
  writeSeed(std::string(dir) + "/tlas", serialize(*t, &refs));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vkrt::accel;
  std::string error;
  if (serializedTopLevel(data, size)) {
    std::vector<std::shared_ptr<const Blas>> refs;
    for (size_t n : {size_t(0), size_t(1), size_t(64)}) {
      refs.resize(n);
      std::shared_ptr<Tlas> tlas = deserializeTlas(data, size, refs, &error);
      (void)tlas;
    }
  } else {
    std::shared_ptr<Blas> blas = deserializeBlas(data, size, &error);
    if (blas) {
      std::vector<uint8_t> again = serialize(*blas);
      (void)again;
    }
  }
  return 0;
}
