// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutFractionMirror
 * @brief   The removed fraction (0-255) of every anatomy voxel as an image, brought up to date brick by brick.
 *
 * The OpenIGTLink bridge sends the removed region to desktop Slicer as a
 * uint8 IMAGE and, after each change, the sub-volume the change touched.
 * Recomputing those voxels' exact removed fractions costs tens of
 * microseconds a voxel on the cut surface: about a tenth of a second of
 * processor time after a pass of a mastoidectomy. Done in Python, that time
 * held the interpreter lock on the bridge's thread and the mouse's drilling
 * waited behind it. This class does it in C++ and its wrapped calls release
 * the lock (VTK_UNBLOCKTHREADS), in slices of a time budget so that the
 * bridge sends poses between them.
 *
 * The field says which bricks changed (their stamps). A voxel's fraction
 * reads the samples one sample around its own, so an update recomputes the
 * voxels of the changed bricks and the one-voxel layer around each, voxel by
 * voxel (vtkVolumeCutField::GetRemovedFraction of its sub-voxels, the values
 * ExportRemovedFraction gives), not the whole neighbouring bricks.
 *
 * Threads: one thread at a time calls this object (the bridge's); the field
 * may be cut meanwhile by its writer (its queries are safe then).
 *
 * @sa vtkVolumeCutField::AppendRemovedVoxelsOfBrick vtkVolumeCutRemovedVoxels
 */

#ifndef vtkVolumeCutFractionMirror_h
#define vtkVolumeCutFractionMirror_h

#include "vtkNew.h"     // For the image and the work arrays
#include "vtkObject.h"
#include "vtkSmartPointer.h" // For the field
#include "vtkType.h"         // For vtkTypeUInt64
#include "vtkVolumeCuttingCoreExport.h" // For export macro
#include "vtkVolumeCutField.h"           // For BrickSize
#include "vtkWrappingHints.h"           // For VTK_UNBLOCKTHREADS

#include <vector> // For the pending bricks

#ifndef VTK_UNBLOCKTHREADS
#define VTK_UNBLOCKTHREADS // VTK before 9.1 wraps without releasing the lock
#endif

class vtkFloatArray;
class vtkIdTypeArray;
class vtkImageData;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutFractionMirror : public vtkObject
{
public:
  static vtkVolumeCutFractionMirror* New();
  vtkTypeMacro(vtkVolumeCutFractionMirror, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Start over on a field: the image gets the anatomy's dimensions (IJK,
   * unsigned char, removed fraction x 255 rounded) and the whole cut as it
   * is now. False (and an error) without an initialized field.
   */
  VTK_UNBLOCKTHREADS
  bool Reset(vtkVolumeCutField* field);

  /**
   * List the voxels the bricks written since the last update may have
   * changed, and their box. False when nothing changed (or an update is
   * already under way: it goes on).
   */
  VTK_UNBLOCKTHREADS
  bool BeginUpdate();

  /**
   * Recompute pending voxels for about budgetSeconds (at least a few). True
   * once none is left: the update's box is then final.
   */
  VTK_UNBLOCKTHREADS
  bool Advance(double budgetSeconds);

  /// Whether bricks of an update are pending.
  bool IsUpdating() const { return this->Next < this->Pending.size(); }

  /// Voxels still pending, and those the current (or last) update listed.
  vtkIdType GetNumberOfPendingVoxels() const { return static_cast<vtkIdType>(this->Pending.size() - this->Next); }
  vtkIdType GetNumberOfUpdateVoxels() const { return static_cast<vtkIdType>(this->Pending.size()); }

  /**
   * The current (or last) update's box in anatomy voxels: i0, i1, j0, j1,
   * k0, k1, lower bounds included, upper excluded.
   */
  void GetUpdateBox(int box[6]) const;

  /// The field's stamp the image follows: what the field had at the last BeginUpdate (or Reset).
  vtkGetMacro(Stamp, vtkTypeUInt64);

  /// The mirrored image (unsigned char, anatomy dimensions); nullptr before Reset.
  vtkImageData* GetImage();

protected:
  vtkVolumeCutFractionMirror();
  ~vtkVolumeCutFractionMirror() override;

  void WriteVoxels(vtkIdTypeArray* ids, vtkFloatArray* fractions);

  vtkSmartPointer<vtkVolumeCutField> Field;
  vtkSmartPointer<vtkImageData> Image;
  vtkNew<vtkIdTypeArray> VoxelIds; // Reset's

  vtkNew<vtkFloatArray> Fractions;
  vtkTypeUInt64 Stamp = 0;
  int AnatomyDimensions[3] = { 0, 0, 0 };
  int VoxelsPerBrick = 1;
  std::vector<vtkIdType> Pending; // anatomy voxel ids of the update, brick by brick
  vtkIdType CopiedBrick = -1;
  bool CopiedBrickWritten = false;
  short Samples[vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize] = {};
  size_t Next = 0;
  int Box[6] = { 0, 0, 0, 0, 0, 0 };

private:
  vtkVolumeCutFractionMirror(const vtkVolumeCutFractionMirror&) = delete;
  void operator=(const vtkVolumeCutFractionMirror&) = delete;
};

#endif
