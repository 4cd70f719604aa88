// The image functions compiled shaders call (OpImageRead/Write/TexelPointer/Fetch/Sample*/*Gather/Query*, on images
// and on texel buffers), by symbol name: the compiler emits calls to these names, and whoever runs compiled code
// supplies their addresses (HostSymbol lists, given to the compiler; the runtime's implementation is
// src/runtime/image_functions.cpp, which reads its image view, buffer view and sampler objects through the
// descriptor records' opaque pointers).
//
// `img` is the record holding the image view (`object`), `smp` the record holding the sampler (`sampler`); for
// a combined image sampler both are the same record. A null record object (unwritten descriptor, index past the
// bound descriptors) reads zeros and writes nothing, as do coordinates outside the view.
//
// Texels travel as four 32-bit words: floats for float/normalized formats, integers for integer formats;
// components a format lacks read as G = B = 0, A = 1. Coordinates travel as four values in the order of the
// view type: 1D (x), 1D array (x, layer), 2D (x, y), 2D array / cube (x, y, layer), 3D (x, y, z).
#pragma once

#include <cstdint>

#include "abi/abi.hpp"

namespace vkrt::abi {

// A function compiled code may call, by the symbol name the compiler emits.
struct HostSymbol {
  const char* name;
  void* address;
};

// vkrt_image_sample_cube / vkrt_image_gather_cube flags.
inline constexpr uint32_t kCubeGrad = 1;  // ddx / ddy given (implicit LOD or Grad); `lod` is then the Bias (NaN: none)
inline constexpr uint32_t kCubeDref = 2;  // a depth comparison with `dref`

}  // namespace vkrt::abi

extern "C" {
// OpImageRead on a storage image.
void vkrt_image_read(const vkrt::abi::DescriptorRecord* img, const int32_t coord[4], uint32_t out[4]);
// OpImageRead on an input attachment (Dim SubpassData): texel (x, y) of layer `layer` (relative to the view's base
// layer) of the view's first mip, sample `sample` of a multisampled image (sample 0 otherwise); zeros outside the
// view or past its samples. No swizzle: input attachment views have the identity swizzle (the spec's
// VUID-VkWriteDescriptorSet-descriptorType-00336 wants identity component mapping for them).
void vkrt_image_read_subpass(const vkrt::abi::DescriptorRecord* img, int32_t x, int32_t y, int32_t layer,
                             int32_t sample, uint32_t out[4]);
// OpImageWrite on a storage image.
void vkrt_image_write(const vkrt::abi::DescriptorRecord* img, const int32_t coord[4], const uint32_t in[4]);
// OpImageTexelPointer (image atomics): the address of texel `coord` of a storage image's first mip, or null when
// the coordinate is outside the view, the record is null or the format is not 32 bits a texel.
void* vkrt_image_texel(const vkrt::abi::DescriptorRecord* img, const int32_t coord[4]);
// OpImageFetch: texel `coord` of mip `lod` (relative to the view's base level), view swizzle applied.
void vkrt_image_fetch(const vkrt::abi::DescriptorRecord* img, const int32_t coord[4], int32_t lod, uint32_t out[4]);
// OpImageSampleExplicitLod with a Lod operand: filtered with the sampler of `smp`, view swizzle applied.
void vkrt_image_sample(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                       const float coord[4], float lod, uint32_t out[4]);
// Sampling with gradients: OpImageSampleImplicitLod in fragment shaders (the coordinates' quad derivatives, with the
// Bias operand, NaN when none) and OpImageSampleExplicitLod with the Grad operand (bias NaN). `ddx`, `ddy`: the
// derivatives of the coordinates (the first dims components count). The level of detail follows "Scale Factor
// Operation" (isotropic: the larger scale factor) and "Level-of-Detail Operation" with the view's base level size,
// the sampler's mipLodBias, minLod and maxLod.
void vkrt_image_sample_grad(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                            const float coord[4], const float ddx[4], const float ddy[4], float bias, uint32_t out[4]);
// The two above with the ConstOffset operand: `offset` (the Dim's components) moves the texels every level's filter
// reads by whole texels.
void vkrt_image_sample_offset(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                              const float coord[4], float lod, const int32_t offset[4], uint32_t out[4]);
void vkrt_image_sample_grad_offset(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                                   const float coord[4], const float ddx[4], const float ddy[4], float bias,
                                   const int32_t offset[4], uint32_t out[4]);
// vkrt_image_sample_grad for the four lanes of a fragment quad in one call (the SPMD path's implicit-LOD and Grad
// sampling, docs/spmd.md): `coord`, `ddx`, `ddy` and `out` hold component k of lane l at [4 k + l], `bias` one per
// lane (NaN: none); only the lanes of bit mask `lanes` are sampled (the others' words are 0). Each lane's result is
// the one vkrt_image_sample_grad gives for its operands; the view and the sampler are resolved once.
void vkrt_image_sample_grad_quad(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                                 const float coord[16], const float ddx[16], const float ddy[16], const float bias[4],
                                 uint32_t lanes, uint32_t out[16]);
// The Dref forms (OpImageSample[Proj]DrefExplicitLod, OpImageSample[Proj]DrefImplicitLod; the compiler divides
// coordinates and `dref` by q for the Proj forms), `offset` null without ConstOffset: each texel's depth (R) is
// compared with `dref` by the sampler's compareOp before filtering ("Depth Compare Operation"); out[0] is the
// filtered 0.0 / 1.0 results.
void vkrt_image_sample_dref(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                            const float coord[4], float lod, float dref, const int32_t offset[4], uint32_t out[4]);
void vkrt_image_sample_grad_dref(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                                 const float coord[4], const float ddx[4], const float ddy[4], float bias, float dref,
                                 const int32_t offset[4], uint32_t out[4]);
// OpImageGather: component `component` (0-3, after the view swizzle) of the four texels the LINEAR filter would read
// in the view's base level ("Texel Gathering"), as (i0j1, i1j1, i1j0, i0j0); zeros unless the view is 2D (array).
void vkrt_image_gather(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                       const float coord[4], int32_t component, uint32_t out[4]);
// OpImageDrefGather: the same four texels' depth comparisons with `dref` (0.0 or 1.0 each).
void vkrt_image_gather_dref(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                            const float coord[4], float dref, uint32_t out[4]);
// Sampling a cube or cube array view (Dim Cube): `coord` is the direction (x, y, z) and, for a cube array, the
// cube's index (a layer of 6 faces). The face and its (s, t) follow "Cube Map Face Selection"; with kCubeGrad the
// level of detail comes from the direction's derivatives projected on the face ("Cube Map Derivation"), plus `lod`
// as the Bias; without, `lod` is the level of detail. LINEAR filtering is seamless: texels past a face's edge are
// read from the adjacent face ("Cube Map Edge Handling"); the sampler's address modes do not apply. Dref: as
// vkrt_image_sample_dref.
void vkrt_image_sample_cube(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                            const float coord[4], const float ddx[4], const float ddy[4], float lod, float dref,
                            uint32_t flags, uint32_t out[4]);
// OpImageGather / OpImageDrefGather on a cube or cube array view: the four texels of the base level the LINEAR filter
// would read on the selected face (across its edges as above).
void vkrt_image_gather_cube(const vkrt::abi::DescriptorRecord* img, const vkrt::abi::DescriptorRecord* smp,
                            const float coord[4], int32_t component, float dref, uint32_t flags, uint32_t out[4]);
// OpImageQuerySize(Lod): the view's size at mip `lod` in view-type order (x, y, z or layers); zeros when null.
void vkrt_image_size(const vkrt::abi::DescriptorRecord* img, int32_t lod, int32_t out[4]);
// OpImageQueryLevels.
int32_t vkrt_image_levels(const vkrt::abi::DescriptorRecord* img);

// Texel buffers (OpTypeImage of Dim Buffer): `buf` is the record holding the buffer view (`object`); `index` is
// the texel index, out of range when negative or past the view's last texel (reads zeros, writes nothing).
// OpImageFetch on a uniform texel buffer, OpImageRead on a storage texel buffer.
void vkrt_texel_buffer_read(const vkrt::abi::DescriptorRecord* buf, int64_t index, uint32_t out[4]);
// OpImageWrite on a storage texel buffer.
void vkrt_texel_buffer_write(const vkrt::abi::DescriptorRecord* buf, int64_t index, const uint32_t in[4]);
// OpImageTexelPointer (texel buffer atomics): the texel's address, or null as for vkrt_image_texel.
void* vkrt_texel_buffer_texel(const vkrt::abi::DescriptorRecord* buf, int64_t index);
// OpImageQuerySize: the view's texel count (0 when null).
int32_t vkrt_texel_buffer_size(const vkrt::abi::DescriptorRecord* buf);
}
