// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingSoftCut (not installed, not wrapped): what the
// implementation files of vtkVolumeCutResectionPlanner share. Each file holds
// one step of the seed paper's section 3:
//   vtkVolumeCutResectionPlanner.cxx                inputs, Plan's box growth, the plan's outputs
//   vtkVolumeCutResectionPlannerOutline.cxx         the outline on the skin, its normals and strips (3.1, 3.2)
//   vtkVolumeCutResectionPlannerShape.cxx           BuildShape: box, shape transform, skin patch, flood fill (3.3)
//   vtkVolumeCutResectionPlannerMask.cxx            BuildMask: the depth under the skin (3.4)
//   vtkVolumeCutResectionPlannerRegion.cxx          BuildRegion and Carve: the region at a depth of cut (3.5)
//   vtkVolumeCutResectionPlannerResectedTissue.cxx  the resected tissue's implicit function, for its mesh
#ifndef vtkVolumeCutResectionPlannerInternals_h
#define vtkVolumeCutResectionPlannerInternals_h

#include "vtkVolumeCutAnatomySampler.h"
#include "vtkVolumeCutResectionPlanner.h"
#include "vtkVolumeCutSoftCutVectors.h"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

class vtkImageData;
class vtkPolyData;

namespace vtkVolumeCutSoftCut
{
/// Everything one plan computes; a new plan is built beside the current one,
/// which it replaces only when complete.
struct PlanData
{
  // The outline and strips in the grid frame (mm along the voxel axes).
  std::vector<Vec> Points;
  std::vector<Vec> Normals;
  std::vector<Vec> Inner;
  std::vector<Vec> Outer;
  Vec AverageNormal{ 0.0, 0.0, 1.0 };
  double Length = 0.0;
  double Area = 0.0;

  int Box[6] = { 0, -1, 0, -1, 0, -1 };
  int Size[3] = { 0, 0, 0 };
  vtkIdType Count = 0;
  std::vector<float> Values;
  std::vector<uint8_t> Class;
  /// Each voxel's nearest strip site, and each site's outline segment.
  std::vector<int> Feature;
  std::unordered_map<int, int> StripSites;
  /// The skin's voxels inside the outline (the patch), in the order found.
  std::vector<vtkIdType> Skin;
  std::vector<float> Wall; // NaN until needed
  std::vector<float> Bone; // NaN until needed
  std::vector<float> Depth;
  vtkIdType FilledCount = 0;
  bool NearFilledReady = false;
  bool MaskReady = false;
  /// Faces of the box (-x, +x, -y, +y, -z, +z) the resection reaches.
  bool Reached[6] = { false, false, false, false, false, false };

  vtkIdType Index(int a, int b, int c) const { return (static_cast<vtkIdType>(c) * this->Size[1] + b) * this->Size[0] + a; }

  /// Ready for a new plan, keeping the arrays' memory (touching fresh pages
  /// costs a plan of a million voxels milliseconds).
  void Reset()
  {
    for (std::vector<Vec>* points : { &this->Points, &this->Normals, &this->Inner, &this->Outer })
    {
      points->clear();
    }
    this->StripSites.clear();
    this->Skin.clear();
    this->FilledCount = 0;
    this->NearFilledReady = false;
    this->MaskReady = false;
    std::fill(this->Reached, this->Reached + 6, false);
  }
};

constexpr uint8_t NearFilled = 8;
/// Components of the region's distances: wall, depth, air margin, bone.
constexpr int RegionComponents = 4;
} // namespace vtkVolumeCutSoftCut

//------------------------------------------------------------------------------
struct vtkVolumeCutResectionPlanner::Internals
{
  using Vec = vtkVolumeCutSoftCut::Vec;
  using PlanData = vtkVolumeCutSoftCut::PlanData;

  /// The CT the planner reads, in the grid frame.
  vtkVolumeCutAnatomySampler Grid;

  std::unique_ptr<PlanData> Current;
  std::unique_ptr<PlanData> Next;
  /// A plan no longer needed, whose arrays the next one reuses.
  std::unique_ptr<PlanData> Spare;
  std::unique_ptr<PlanData> NewPlan()
  {
    std::unique_ptr<PlanData> plan = std::move(this->Spare);
    if (!plan)
    {
      plan.reset(new PlanData);
    }
    plan->Reset();
    return plan;
  }
  /// Working arrays of the transforms, kept between plans (a new plan of
  /// the same size then touches no fresh memory).
  std::vector<unsigned char> Sites;
  std::vector<float> Work;
  std::vector<int> Scratch;
  std::vector<int> Nearest;
  /// Voxels added to each face of the box by growth, for the inputs of GrowthTime.
  int Growth[6] = { 0, 0, 0, 0, 0, 0 };
  vtkMTimeType GrowthTime = 0;

  ///@{
  /**
   * The first steps of BuildShape (vtkVolumeCutResectionPlannerOutline.cxx);
   * each returns false after planner.Fail. ReadOutline: the outline's
   * distinct points in the grid frame, each checked to lie on the skin
   * (this replaces no plan yet). PlaceOutline: the outline resampled evenly
   * onto the skin, and the step of that resampling along the given outline
   * (mm). BuildStrips: the normals, the average normal, the projected area,
   * the strips, and for each outline point the unit vector towards the
   * inner strip and the strips' offset (mm).
   */
  bool ReadOutline(vtkVolumeCutResectionPlanner& planner, std::vector<Vec>& given);
  bool PlaceOutline(vtkVolumeCutResectionPlanner& planner, const std::vector<Vec>& given, PlanData& plan, double& step);
  bool BuildStrips(vtkVolumeCutResectionPlanner& planner, double step, PlanData& plan, std::vector<Vec>& inward, double& offset);
  ///@}

  /// A closed polyline through grid-frame points, in RAS.
  void MakePolyline(const std::vector<Vec>& points, vtkPolyData* polyline) const;

  /// One of the current plan's polylines (outline, strips) in RAS; empty without a plan.
  void CopyPolyline(std::vector<Vec> PlanData::*which, vtkPolyData* polyline) const;

  /// The current plan, with image emptied and given the box's extent; nullptr without either.
  const PlanData* StartBoxImage(vtkImageData* image) const;
};

#endif
