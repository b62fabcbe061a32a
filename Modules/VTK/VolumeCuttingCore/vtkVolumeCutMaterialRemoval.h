// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutMaterialRemoval
 * @brief   Drilling that removes bone at a rate, not at once (Morris et al.).
 *
 * Instead of removing the burr's whole volume at contact, each sub-voxel
 * sample inside the burr accumulates exposure at the drilling power where it
 * touches, and is removed once its exposure reaches what its bone density
 * requires. Power depends on the sample's distance from the burr axis and on
 * the burr type; density comes from the CT in Hounsfield units, so cortical
 * bone takes longer than trabecular bone. Everything is a function of the
 * inputs: replaying the same poses and time steps gives the same cut.
 *
 * Model (all parameters settable):
 * - power fraction at distance rho from the axis of a burr of radius r:
 *   cutting burr rho / r (flutes cut with their surface speed); diamond burr
 *   DiamondEfficiency * (0.25 + 0.75 rho / r) (abrasive, more even, slower);
 * - time at full power to remove one sample: (max(HU, 0) / 1000 + 0.05) *
 *   sub-voxel size / RemovalRate, RemovalRate being the depth per second a
 *   cutting burr's equator advances in bone of density 1 (1000 HU).
 * Removed samples take the burr's distance, through the cut field's usual
 * writer (protection, contacts, stamps and undo apply).
 */

#ifndef vtkVolumeCutMaterialRemoval_h
#define vtkVolumeCutMaterialRemoval_h

#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <array>         // For the exposure of a brick
#include <unordered_map> // For the exposure map

class vtkImageData;
class vtkVolumeCutField;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutMaterialRemoval : public vtkObject
{
public:
  static vtkVolumeCutMaterialRemoval* New();
  vtkTypeMacro(vtkVolumeCutMaterialRemoval, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum BurrType
  {
    CuttingBurr = 0,
    DiamondBurr = 1
  };

  ///@{
  /// Set/get the burr type. Default is CuttingBurr.
  vtkSetClampMacro(BurrType, int, CuttingBurr, DiamondBurr);
  vtkGetMacro(BurrType, int);
  ///@}

  ///@{
  /// Set/get the depth per second (mm/s) a cutting burr's equator removes in
  /// bone of density 1 (1000 HU). Default is 2.
  vtkSetClampMacro(RemovalRate, double, 1e-6, 1e6);
  vtkGetMacro(RemovalRate, double);
  ///@}

  ///@{
  /// Set/get the diamond burr's efficiency relative to a cutting burr. Default 0.35.
  vtkSetClampMacro(DiamondEfficiency, double, 0.0, 1.0);
  vtkGetMacro(DiamondEfficiency, double);
  ///@}

  /**
   * The field to cut and the anatomy (Hounsfield units, the field's anatomy
   * dimensions, one component). Resets the accumulated exposure. Returns false
   * (and an error) if they do not match.
   */
  bool SetInputs(vtkVolumeCutField* field, vtkImageData* hounsfieldUnits);

  /// SetInputs only if either input differs from the current ones (keeps the
  /// exposure otherwise).
  bool SetInputsIfChanged(vtkVolumeCutField* field, vtkImageData* hounsfieldUnits);

  /**
   * Drill for dt seconds with a spherical burr of the given radius (mm) at
   * center, its shaft along axis (RAS). Returns false (and an error), changing
   * nothing, for non-finite inputs, a radius or dt that is not positive, or
   * no inputs.
   */
  bool Drill(const double center[3], const double axis[3], double radius, double dt);

  /// Forget the accumulated exposure (a new drilling session on the same field).
  void ResetExposure();

protected:
  vtkVolumeCutMaterialRemoval();
  ~vtkVolumeCutMaterialRemoval() override;

  int BurrType = CuttingBurr;
  double RemovalRate = 2.0;
  double DiamondEfficiency = 0.35;
  vtkVolumeCutField* Field = nullptr;
  vtkImageData* HounsfieldUnits = nullptr;
  std::unordered_map<vtkIdType, std::array<float, 512>> Exposure;

private:
  vtkVolumeCutMaterialRemoval(const vtkVolumeCutMaterialRemoval&) = delete;
  void operator=(const vtkVolumeCutMaterialRemoval&) = delete;
};

#endif
