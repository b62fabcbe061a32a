// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped): the scene
// that vtkVolumeCutRayCaster's rays read, its inputs copied onto the
// anatomy's grid. PrepareScene writes it once per frame; the ray stages
// (vtkVolumeCutSampleClassifier, vtkVolumeCutBorderLocator,
// vtkVolumeCutPieceClassifier, vtkVolumeCutSurfaceShader,
// vtkVolumeCutThinBoneShader, vtkVolumeCutCompositor) only read it, so the
// threads casting rays share it without locks.
#ifndef vtkVolumeCutRayScene_h
#define vtkVolumeCutRayScene_h

#include "vtkVolumeCutEmptySpace.h"
#include "vtkVolumeCutRayMath.h"

#include <vtkType.h>

#include <cstdint>
#include <vector>

class vtkVolumeCutField;

struct vtkVolumeCutRayScene
{
  static constexpr int MaximumCutFields = 8;
  static constexpr int MaximumFractions = 16;
  static constexpr int TransferTableSize = 4096;

  /// How a segment looks and where its surface is.
  struct SegmentStyle
  {
    float Color[3] = { 1.f, 1.f, 1.f };        // of cut and clip surfaces
    float SurfaceColor[3] = { 1.f, 1.f, 1.f }; // of the segment's own (uncut) surface
    float Opacity = 0.f;
    float Iso = 0.f;
    bool Shape = false; // the surface is the label's own indicator at 0.5
    bool Defined = false;
  };

  /// Edge of the blocks of cells over which fractions record where they are above 0.
  static constexpr int FractionBlockSize = 8;

  /// One segment's fractional labelmap: the fraction (0..1) of each voxel.
  struct FractionVolume
  {
    int Label = 0;
    std::vector<float> Values;
    /// Per block of FractionBlockSize^3 cells (x fastest), whether a corner
    /// of one of its cells has a fraction above 0; empty: not known. A
    /// segment covers a few percent of the volume (a smoothed one a little
    /// more): elsewhere its interpolated fraction is exactly 0, and a sample
    /// weighing it there reads none of its corners, far apart in memory.
    std::vector<uint8_t> NonZeroBlocks;
  };

  struct PlaneEquation
  {
    double Normal[3];
    double Offset;
  };

  // The anatomy (CT values as floats) and where its voxels are.
  std::vector<float> Values;
  int Dimensions[3] = { 0, 0, 0 };
  double IJKToWorld[16];
  double WorldToIJK[16];
  /// Inverse transpose of IJK-to-world's linear part (4x4, row-major): maps
  /// IJK gradients to world normals.
  double NormalMatrix[16];
  /// Millimetres per index unit across each axis's faces (1 / the norm of
  /// world-to-IJK's row): a sample's distance to the volume's faces, once per render.
  double MillimetresPerIndex[3] = { 1.0, 1.0, 1.0 };

  // Segments: the label map, fractional labelmaps and each label's style.
  std::vector<uint16_t> Labels;
  std::vector<FractionVolume> Fractions;
  std::vector<SegmentStyle> Styles;
  /// A visible segment is drawn at a CT iso-value (not by its own shape), and the lowest such value.
  bool AnyIsoSegment = false;
  double MinimumIso = 0.0;
  /// A visible segment is drawn by its own shape (its indicator at 0.5),
  /// whatever the CT value.
  bool AnyShapeSegment = false;

  bool HasSegments() const { return !this->Labels.empty() || !this->Fractions.empty(); }

  /// The fraction blocks along each axis, and the block of a cell.
  void GetFractionBlockDimensions(int blocks[3]) const
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      blocks[axis] = (this->Dimensions[axis] - 1 + FractionBlockSize - 1) / FractionBlockSize;
    }
  }
  vtkIdType FractionBlockOf(const int cell[3]) const
  {
    int blocks[3];
    this->GetFractionBlockDimensions(blocks);
    return cell[0] / FractionBlockSize +
      static_cast<vtkIdType>(blocks[0]) * (cell[1] / FractionBlockSize + static_cast<vtkIdType>(blocks[1]) * (cell[2] / FractionBlockSize));
  }

  /// Cut fields with removed material, on the anatomy's grid.
  std::vector<vtkVolumeCutField*> CutFields;
  std::vector<PlaneEquation> Planes;

  // Composite mode: the transfer functions as tables over TableRange.
  std::vector<float> ColorTable;   // 3 per entry
  std::vector<float> OpacityTable; // per entry, per ScalarOpacityUnitDistance
  double TableRange[2] = { 0.0, 1.0 };

  vtkVolumeCutEmptySpace EmptySpace;

  // The caster's settings for this frame.
  int BlendMode = 0;
  double SampleDistance = 0.5;
  double GradientStep = 0.3;
  double UnitDistance = 1.0;
  bool ThinBone = false;
  double ThinBoneThickness = 1.0;
  bool AmbientOcclusion = false;
  double AmbientOcclusionRadius = 6.0;
  double Ambient = 0.25, Diffuse = 0.7, Specular = 0.2, SpecularPower = 20.0;
};

#endif
