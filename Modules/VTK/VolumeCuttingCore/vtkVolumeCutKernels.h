// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped).
//
// The cut field's writer runs a few loops over every sample of every brick a
// stroke touches (tool distances, quantisation, merging): they decide whether
// a stroke fits the haptic frame. Each is compiled once per instruction set
// from vtkVolumeCutKernelsImpl.h (baseline everywhere; AVX2 and AVX-512 where
// the compiler targets x86-64, whichever compiler it is), and Get() hands out
// the widest set the processor runs. All sets round alike (no contraction),
// so replays stay bitwise reproducible from one machine to the next.
#ifndef vtkVolumeCutKernels_h
#define vtkVolumeCutKernels_h

#include <cstdint>

namespace vtkVolumeCutKernels
{
/// Samples of one brick (vtkVolumeCutField::BrickSize cubed).
constexpr int SamplesPerBrick = 512;
/// The field's 16-bit extremes: removed, and untouched.
constexpr int16_t Outside = 32767;
constexpr int16_t Inside = -32767;

enum InstructionSet
{
  Baseline = 0,
  AVX2 = 1,
  AVX512 = 2,
  NumberOfInstructionSets = 3
};

struct Table
{
  /// Distances (mm, negative inside) of a brick's samples at w0 + offsets
  /// from the capsule of segment ab (from the origin) and radius; samples
  /// with (w . ab) / |ab|^2 below behindLimit are given far instead.
  void (*CapsuleBrickDistances)(const float w0[3], const float ab[3], float inverseLength2, float radius, float behindLimit, float far,
    const float* offsets, float* distances);
  /// count of a brick's samples (w0 + offsets; offsets points into the x
  /// run of the brick's offsets, the y and z runs SamplesPerBrick and twice
  /// that further) rotated into a tool's frame (rotation is tool-to-RAS):
  /// x, y and z runs.
  void (*ToToolFrame)(const float rotation[3][3], const float w0[3], const float* offsets, int count, float* x, float* y, float* z);
  /// distances = min(distances, copy) where the sample is within reach of
  /// the copy's centre (farther, a tool's distance may underestimate).
  void (*MergeCopy)(const float* x, const float* y, const float* z, const float* copy, float reach2, float* distances);
  /// Distances to 16-bit samples: scaled, clamped to the band, rounded.
  void (*QuantizeRun)(const float* distances, int count, float scale, int16_t* quantized);
  /// merged = min(current, quantized); whether any sample changed.
  bool (*MinimumRun)(const int16_t* quantized, const int16_t* current, int count, int16_t* merged);
  /// Signed distances to tools centred at the origin of their own frame.
  void (*CylinderDistances)(float radius, float halfLength, const float* x, const float* y, const float* z, int count, float* distances);
  void (*EllipsoidDistances)(const float inverse[3], const float inverse2[3], float centre, const float* x, const float* y, const float* z,
    int count, float* distances);
  void (*BoxDistances)(const float half[3], const float* x, const float* y, const float* z, int count, float* distances);
  /// distances = min(distances, distance to a cylinder swept across its
  /// cross-section): the disk of radius about offset (x, y) moved along
  /// segment (x, y), times the slab offset[2] +- halfLength.
  void (*CylinderSweptMinimum)(float radius, float halfLength, const float offset[3], const float segment[2], float inverseSegmentLength2,
    const float* x, const float* y, const float* z, int count, float* distances);
  /// The same distances stored, not merged: the first piece of a sweep.
  void (*CylinderSwept)(float radius, float halfLength, const float offset[3], const float segment[2], float inverseSegmentLength2,
    const float* x, const float* y, const float* z, int count, float* distances);
};

/// The kernels of the set in use: the widest this build and processor have,
/// unless Select() chose another.
const Table& Get();

/// Whether this build has the set and this processor (and its operating
/// system) runs it.
bool IsAvailable(int set);
/// Use this set from now on, process-wide; false (nothing changes) if it is
/// not available.
bool Select(int set);
int GetSelected();
const char* GetName(int set);

// One table per compiled set (vtkVolumeCutKernels<Set>.cxx).
extern const Table BaselineTable;
extern const Table AVX2Table;
extern const Table AVX512Table;
}

#endif
