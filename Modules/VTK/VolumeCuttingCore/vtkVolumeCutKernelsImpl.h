// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore: the bodies of vtkVolumeCutKernels.h, included
// once by each vtkVolumeCutKernels<Set>.cxx, which defines
// VOLUMECUTTING_KERNELS_TABLE and is compiled for that instruction set.
//
// Everything here has internal linkage and calls nothing inline from a
// library header (std::sqrt, std::min, ... are inline functions: an unoptimised
// build would emit them here, compiled for AVX2, and the linker could pick
// that copy for the whole program). sqrtf and fabsf are C functions: inlined as
// instructions when optimising, called in the C library otherwise.
// Testing/Cxx/CheckKernelSymbols.cmake checks the objects for it.
#ifndef VOLUMECUTTING_KERNELS_TABLE
#error "define VOLUMECUTTING_KERNELS_TABLE before including vtkVolumeCutKernelsImpl.h"
#endif

#include "vtkVolumeCutKernels.h"

#include <math.h>

namespace
{
using vtkVolumeCutKernels::SamplesPerBrick;

void CapsuleBrickDistances(const float w0[3], const float ab[3], float inverseLength2, float radius, float behindLimit, float far,
  const float* offsets, float* distances)
{
  for (int n = 0; n < SamplesPerBrick; ++n)
  {
    const float wx = w0[0] + offsets[n];
    const float wy = w0[1] + offsets[SamplesPerBrick + n];
    const float wz = w0[2] + offsets[2 * SamplesPerBrick + n];
    const float ahead = (wx * ab[0] + wy * ab[1] + wz * ab[2]) * inverseLength2;
    float along = ahead < 0.0f ? 0.0f : ahead;
    along = along > 1.0f ? 1.0f : along;
    const float dx = wx - along * ab[0];
    const float dy = wy - along * ab[1];
    const float dz = wz - along * ab[2];
    const float distance = sqrtf(dx * dx + dy * dy + dz * dz) - radius;
    distances[n] = ahead < behindLimit ? far : distance;
  }
}

void ToToolFrame(const float rotation[3][3], const float w0[3], const float* __restrict offsets, int count, float* __restrict x,
  float* __restrict y, float* __restrict z)
{
  // Locals: the stores below cannot then be taken to change them.
  const float r00 = rotation[0][0], r01 = rotation[0][1], r02 = rotation[0][2];
  const float r10 = rotation[1][0], r11 = rotation[1][1], r12 = rotation[1][2];
  const float r20 = rotation[2][0], r21 = rotation[2][1], r22 = rotation[2][2];
  const float w0x = w0[0], w0y = w0[1], w0z = w0[2];
  for (int n = 0; n < count; ++n)
  {
    const float wx = w0x + offsets[n];
    const float wy = w0y + offsets[SamplesPerBrick + n];
    const float wz = w0z + offsets[2 * SamplesPerBrick + n];
    x[n] = r00 * wx + r10 * wy + r20 * wz;
    y[n] = r01 * wx + r11 * wy + r21 * wz;
    z[n] = r02 * wx + r12 * wy + r22 * wz;
  }
}

void MergeCopy(const float* __restrict x, const float* __restrict y, const float* __restrict z, const float* __restrict copy, float reach2,
  float* __restrict distances)
{
  for (int n = 0; n < SamplesPerBrick; ++n)
  {
    const float centre2 = x[n] * x[n] + y[n] * y[n] + z[n] * z[n];
    const float candidate = centre2 <= reach2 ? copy[n] : distances[n];
    distances[n] = candidate < distances[n] ? candidate : distances[n];
  }
}

void QuantizeRun(const float* distances, int count, float scale, int16_t* quantized)
{
  const float insideF = static_cast<float>(vtkVolumeCutKernels::Inside);
  const float outsideF = static_cast<float>(vtkVolumeCutKernels::Outside);
  for (int n = 0; n < count; ++n)
  {
    float scaled = distances[n] * scale;
    scaled = scaled < insideF ? insideF : scaled;
    scaled = scaled > outsideF ? outsideF : scaled;
    // Round to nearest through truncation of a positive number.
    quantized[n] = static_cast<int16_t>(static_cast<int>(scaled + 32768.5f) - 32768);
  }
}

bool MinimumRun(const int16_t* quantized, const int16_t* current, int count, int16_t* merged)
{
  int changed = 0;
  for (int n = 0; n < count; ++n)
  {
    merged[n] = quantized[n] < current[n] ? quantized[n] : current[n];
    changed |= merged[n] != current[n];
  }
  return changed != 0;
}

void CylinderDistances(float radius, float halfLength, const float* x, const float* y, const float* z, int count, float* distances)
{
  for (int n = 0; n < count; ++n)
  {
    const float radial = sqrtf(x[n] * x[n] + y[n] * y[n]) - radius;
    const float axial = fabsf(z[n]) - halfLength;
    const float outsideRadial = radial > 0.0f ? radial : 0.0f;
    const float outsideAxial = axial > 0.0f ? axial : 0.0f;
    const float larger = radial > axial ? radial : axial;
    distances[n] = sqrtf(outsideRadial * outsideRadial + outsideAxial * outsideAxial) + (larger < 0.0f ? larger : 0.0f);
  }
}

void EllipsoidDistances(const float inverse[3], const float inverse2[3], float centre, const float* x, const float* y, const float* z, int count,
  float* distances)
{
  for (int n = 0; n < count; ++n)
  {
    const float sx = x[n] * inverse[0];
    const float sy = y[n] * inverse[1];
    const float sz = z[n] * inverse[2];
    const float tx = x[n] * inverse2[0];
    const float ty = y[n] * inverse2[1];
    const float tz = z[n] * inverse2[2];
    const float k0 = sqrtf(sx * sx + sy * sy + sz * sz);
    const float k1 = sqrtf(tx * tx + ty * ty + tz * tz);
    const float safe = k1 > 0.0f ? k1 : 1.0f;
    distances[n] = k1 > 0.0f ? k0 * (k0 - 1.0f) / safe : centre;
  }
}

void BoxDistances(const float half[3], const float* x, const float* y, const float* z, int count, float* distances)
{
  for (int n = 0; n < count; ++n)
  {
    const float ex = fabsf(x[n]) - half[0];
    const float ey = fabsf(y[n]) - half[1];
    const float ez = fabsf(z[n]) - half[2];
    const float ox = ex > 0.0f ? ex : 0.0f;
    const float oy = ey > 0.0f ? ey : 0.0f;
    const float oz = ez > 0.0f ? ez : 0.0f;
    float largest = ex > ey ? ex : ey;
    largest = largest > ez ? largest : ez;
    distances[n] = sqrtf(ox * ox + oy * oy + oz * oz) + (largest < 0.0f ? largest : 0.0f);
  }
}
template <bool Minimum>
void CylinderSweptRun(float radius, float halfLength, const float offset[3], const float segment[2], float inverseSegmentLength2,
  const float* x, const float* y, const float* z, int count, float* __restrict distances)
{
  const float ox = offset[0], oy = offset[1], oz = offset[2];
  const float sx = segment[0], sy = segment[1];
  for (int n = 0; n < count; ++n)
  {
    // The cross-section: distance to the segment, less the radius (a 2D capsule).
    const float px = x[n] - ox;
    const float py = y[n] - oy;
    float along = (px * sx + py * sy) * inverseSegmentLength2;
    along = along < 0.0f ? 0.0f : along;
    along = along > 1.0f ? 1.0f : along;
    const float dx = px - along * sx;
    const float dy = py - along * sy;
    const float radial = sqrtf(dx * dx + dy * dy) - radius;
    // Times the slab: as a cylinder's distance combines its disk and its length.
    const float axial = fabsf(z[n] - oz) - halfLength;
    const float outsideRadial = radial > 0.0f ? radial : 0.0f;
    const float outsideAxial = axial > 0.0f ? axial : 0.0f;
    const float larger = radial > axial ? radial : axial;
    const float distance = sqrtf(outsideRadial * outsideRadial + outsideAxial * outsideAxial) + (larger < 0.0f ? larger : 0.0f);
    if (Minimum)
    {
      distances[n] = distance < distances[n] ? distance : distances[n];
    }
    else
    {
      distances[n] = distance;
    }
  }
}

void CylinderSweptMinimum(float radius, float halfLength, const float offset[3], const float segment[2], float inverseSegmentLength2,
  const float* x, const float* y, const float* z, int count, float* distances)
{
  CylinderSweptRun<true>(radius, halfLength, offset, segment, inverseSegmentLength2, x, y, z, count, distances);
}

void CylinderSwept(float radius, float halfLength, const float offset[3], const float segment[2], float inverseSegmentLength2, const float* x,
  const float* y, const float* z, int count, float* distances)
{
  CylinderSweptRun<false>(radius, halfLength, offset, segment, inverseSegmentLength2, x, y, z, count, distances);
}
} // namespace

const vtkVolumeCutKernels::Table vtkVolumeCutKernels::VOLUMECUTTING_KERNELS_TABLE = { CapsuleBrickDistances, ToToolFrame, MergeCopy, QuantizeRun,
  MinimumRun, CylinderDistances, EllipsoidDistances, BoxDistances, CylinderSweptMinimum, CylinderSwept };
