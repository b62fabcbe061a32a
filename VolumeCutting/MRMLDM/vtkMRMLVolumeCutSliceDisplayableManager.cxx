/*==============================================================================

  VolumeCutting
  Licensed under the Apache License, Version 2.0 (the "License");

==============================================================================*/

#include "vtkMRMLVolumeCutSliceDisplayableManager.h"

#include "vtkMRMLVolumeCutNode.h"
#include "vtkVolumeCutField.h"

#include <vtkMRMLScene.h>
#include <vtkMRMLSliceNode.h>

#include <vtkActor2D.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges2D.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty2D.h>
#include <vtkRenderer.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>
#include <vtkWeakPointer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

vtkStandardNewMacro(vtkMRMLVolumeCutSliceDisplayableManager);

namespace
{
/// The slice plane of a view: RAS = Origin + x AxisX + y AxisY for view XY
/// coordinates (pixels), and the signed height (mm) of a RAS point over it.
/// Solving the 2x2 normal equations instead of inverting XYToRAS keeps this
/// independent of the matrix's third column (slab thickness, possibly 0).
struct SlicePlane
{
  double Origin[3];
  double AxisX[3];
  double AxisY[3];
  double Normal[3];
  double InverseGram[2][2];

  bool Set(vtkMatrix4x4* xyToRas)
  {
    for (int row = 0; row < 3; ++row)
    {
      this->AxisX[row] = xyToRas->GetElement(row, 0);
      this->AxisY[row] = xyToRas->GetElement(row, 1);
      this->Origin[row] = xyToRas->GetElement(row, 3);
    }
    vtkMath::Cross(this->AxisX, this->AxisY, this->Normal);
    const double xx = vtkMath::Dot(this->AxisX, this->AxisX);
    const double xy = vtkMath::Dot(this->AxisX, this->AxisY);
    const double yy = vtkMath::Dot(this->AxisY, this->AxisY);
    const double determinant = xx * yy - xy * xy;
    if (!(determinant > 1e-12 * xx * yy) || vtkMath::Normalize(this->Normal) == 0.0)
    {
      return false;
    }
    this->InverseGram[0][0] = yy / determinant;
    this->InverseGram[0][1] = -xy / determinant;
    this->InverseGram[1][0] = -xy / determinant;
    this->InverseGram[1][1] = xx / determinant;
    return true;
  }

  /// View XY (pixels) and height over the plane (mm) of a RAS point.
  void ToXYH(const double ras[3], double xyh[3]) const
  {
    const double relative[3] = { ras[0] - this->Origin[0], ras[1] - this->Origin[1], ras[2] - this->Origin[2] };
    const double alongX = vtkMath::Dot(relative, this->AxisX);
    const double alongY = vtkMath::Dot(relative, this->AxisY);
    xyh[0] = this->InverseGram[0][0] * alongX + this->InverseGram[0][1] * alongY;
    xyh[1] = this->InverseGram[1][0] * alongX + this->InverseGram[1][1] * alongY;
    xyh[2] = vtkMath::Dot(relative, this->Normal);
  }

  void ToRAS(double x, double y, double ras[3]) const
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      ras[axis] = this->Origin[axis] + x * this->AxisX[axis] + y * this->AxisY[axis];
    }
  }
};

/// An axis-aligned rectangle of view XY coordinates.
struct ViewRectangle
{
  double Lower[2]{ VTK_DOUBLE_MAX, VTK_DOUBLE_MAX };
  double Upper[2]{ -VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };

  void Add(const double point[2])
  {
    for (int axis = 0; axis < 2; ++axis)
    {
      this->Lower[axis] = std::min(this->Lower[axis], point[axis]);
      this->Upper[axis] = std::max(this->Upper[axis], point[axis]);
    }
  }
  bool IsEmpty() const { return this->Lower[0] > this->Upper[0] || this->Lower[1] > this->Upper[1]; }
  void Clip(const ViewRectangle& window)
  {
    for (int axis = 0; axis < 2; ++axis)
    {
      this->Lower[axis] = std::max(this->Lower[axis], window.Lower[axis]);
      this->Upper[axis] = std::min(this->Upper[axis], window.Upper[axis]);
    }
  }
};

/// Where the plane crosses the part of the field that the cut can reach: the
/// XY bounding rectangles of the sections of the reach of every allocated
/// brick holding a sample near or inside the removed region, within the
/// window. A point of the field is interpolated from the 2^3 samples around
/// it, so samples of brick b reach sub-voxel indices (8b - 1, 8b + 8); the
/// curvature correction lowers a value by at most a quarter of the sum of the
/// sub-voxel spacings (vtkVolumeCutField::GetSignedDistance), so where every
/// sample around a point exceeds that, the point is outside the removed
/// region. Twice that bound is used, plus two quanta of rounding.
std::vector<ViewRectangle> BrickSections(vtkVolumeCutField* field, const SlicePlane& plane, const ViewRectangle& window)
{
  std::vector<ViewRectangle> sections;
  vtkNew<vtkIdList> bricks;
  field->GetBricksModifiedSince(0, bricks);
  if (bricks->GetNumberOfIds() == 0)
  {
    return sections;
  }
  double subVoxel[3];
  field->GetSubVoxelSpacing(subVoxel);
  const double nearSurface = (0.5 * (subVoxel[0] + subVoxel[1] + subVoxel[2]) + 2.0 * field->GetQuantum()) / field->GetQuantum();
  // Sub-voxel index -> (x, y, height): affine, so one origin and three steps.
  vtkNew<vtkMatrix4x4> indexToRas;
  field->GetSubVoxelIJKToRAS(indexToRas);
  double origin[3];
  double steps[3][3];
  {
    const double zero[3] = { indexToRas->GetElement(0, 3), indexToRas->GetElement(1, 3), indexToRas->GetElement(2, 3) };
    plane.ToXYH(zero, origin);
    for (int axis = 0; axis < 3; ++axis)
    {
      const double unit[3] = { zero[0] + indexToRas->GetElement(0, axis), zero[1] + indexToRas->GetElement(1, axis),
        zero[2] + indexToRas->GetElement(2, axis) };
      plane.ToXYH(unit, steps[axis]);
      for (int component = 0; component < 3; ++component)
      {
        steps[axis][component] -= origin[component];
      }
    }
  }
  int brickDimensions[3];
  field->GetBrickDimensions(brickDimensions);
  constexpr int size = vtkVolumeCutField::BrickSize;
  std::vector<short> samples(size * size * size);
  for (vtkIdType n = 0; n < bricks->GetNumberOfIds(); ++n)
  {
    const vtkIdType id = bricks->GetId(n);
    const vtkIdType brick[3] = { id % brickDimensions[0], (id / brickDimensions[0]) % brickDimensions[1],
      id / (static_cast<vtkIdType>(brickDimensions[0]) * brickDimensions[1]) };
    std::array<std::array<double, 3>, 8> corners;
    double lowest = VTK_DOUBLE_MAX;
    double highest = -VTK_DOUBLE_MAX;
    for (int corner = 0; corner < 8; ++corner)
    {
      for (int component = 0; component < 3; ++component)
      {
        double value = origin[component];
        for (int axis = 0; axis < 3; ++axis)
        {
          const double index = ((corner >> axis) & 1) ? brick[axis] * size + size : brick[axis] * size - 1.0;
          value += index * steps[axis][component];
        }
        corners[corner][component] = value;
      }
      lowest = std::min(lowest, corners[corner][2]);
      highest = std::max(highest, corners[corner][2]);
    }
    if (lowest > 0.0 || highest < 0.0)
    {
      continue;
    }
    field->CopyBrick(id, samples.data());
    if (*std::min_element(samples.begin(), samples.end()) >= nearSurface)
    {
      continue;
    }
    // The section is a polygon whose vertices lie on the box's edges.
    ViewRectangle section;
    for (int corner = 0; corner < 8; ++corner)
    {
      const auto& a = corners[corner];
      if (a[2] == 0.0)
      {
        section.Add(a.data());
      }
      for (int axis = 0; axis < 3; ++axis)
      {
        if ((corner >> axis) & 1)
        {
          continue;
        }
        const auto& b = corners[corner | (1 << axis)];
        if ((a[2] < 0.0 && b[2] > 0.0) || (a[2] > 0.0 && b[2] < 0.0))
        {
          const double t = a[2] / (a[2] - b[2]);
          const double point[2] = { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]) };
          section.Add(point);
        }
      }
    }
    section.Clip(window);
    if (!section.IsEmpty())
    {
      sections.push_back(section);
    }
  }
  return sections;
}

/// Signed distances of the field on a grid of view XY coordinates over the
/// part of the plane that the cut can reach within the view and a margin
/// around it (BrickSections). The grid is spaced at the field's smallest
/// sub-voxel spacing, or finer (down to a quarter of it) where a view pixel
/// is smaller, so outlines stay smooth when zoomed in; coarser only when it
/// would exceed maximumSamples.
///
/// Every grid edge that the zero level crosses has both ends evaluated
/// exactly: samples one step beyond the reach are evaluated too (they are
/// positive), and the grid's outermost ring, one step farther, is set
/// uncut. The zero level is then a set of closed loops, which a polygon fill
/// needs; where the margin cuts through the removed region the loops close
/// along the margin, outside the view.
struct Sampling
{
  vtkSmartPointer<vtkImageData> Image;
  double Spacing = 0.0;
  vtkIdType Evaluated = 0;
  bool Coarsened = false;
};

Sampling SampleSection(vtkVolumeCutField* field, const SlicePlane& plane, const int dimensions[2], double marginPixels, vtkIdType maximumSamples)
{
  Sampling result;
  double subVoxel[3];
  field->GetSubVoxelSpacing(subVoxel);
  const double finest = std::min({ subVoxel[0], subVoxel[1], subVoxel[2] });
  const double pixel[2] = { vtkMath::Norm(plane.AxisX), vtkMath::Norm(plane.AxisY) };
  double spacing = std::min(finest, std::max(std::min(pixel[0], pixel[1]), 0.25 * finest));
  const double margin = marginPixels + 2.0 * spacing / std::min(pixel[0], pixel[1]);
  ViewRectangle window;
  window.Lower[0] = window.Lower[1] = -margin;
  window.Upper[0] = dimensions[0] + margin;
  window.Upper[1] = dimensions[1] + margin;
  const std::vector<ViewRectangle> sections = BrickSections(field, plane, window);
  if (sections.empty())
  {
    return result;
  }

  double step[2];
  std::vector<std::array<vtkIdType, 4>> ranges(sections.size()); // first i, last i, first j, last j
  vtkIdType lower[2];
  vtkIdType count[2];
  for (;;)
  {
    vtkIdType gridLower[2] = { VTK_ID_MAX, VTK_ID_MAX };
    vtkIdType gridUpper[2] = { VTK_ID_MIN, VTK_ID_MIN };
    for (int axis = 0; axis < 2; ++axis)
    {
      step[axis] = spacing / pixel[axis];
    }
    for (size_t n = 0; n < sections.size(); ++n)
    {
      for (int axis = 0; axis < 2; ++axis)
      {
        ranges[n][2 * axis] = static_cast<vtkIdType>(std::floor(sections[n].Lower[axis] / step[axis])) - 1;
        ranges[n][2 * axis + 1] = static_cast<vtkIdType>(std::ceil(sections[n].Upper[axis] / step[axis])) + 1;
        gridLower[axis] = std::min(gridLower[axis], ranges[n][2 * axis] - 1);
        gridUpper[axis] = std::max(gridUpper[axis], ranges[n][2 * axis + 1] + 1);
      }
    }
    for (int axis = 0; axis < 2; ++axis)
    {
      lower[axis] = std::max(gridLower[axis], static_cast<vtkIdType>(std::ceil(window.Lower[axis] / step[axis])));
      count[axis] = std::min(gridUpper[axis], static_cast<vtkIdType>(std::floor(window.Upper[axis] / step[axis]))) - lower[axis] + 1;
    }
    const double total = static_cast<double>(count[0]) * static_cast<double>(count[1]);
    if (total <= static_cast<double>(maximumSamples))
    {
      break;
    }
    spacing *= 1.01 * std::sqrt(total / static_cast<double>(maximumSamples));
    result.Coarsened = true;
  }
  if (count[0] < 3 || count[1] < 3)
  {
    return result;
  }

  // Inner samples to evaluate; the outermost ring stays uncut.
  std::vector<uint8_t> reached(static_cast<size_t>(count[0] * count[1]), 0);
  for (const auto& range : ranges)
  {
    const vtkIdType first[2] = { std::max<vtkIdType>(1, range[0] - lower[0]), std::max<vtkIdType>(1, range[2] - lower[1]) };
    const vtkIdType last[2] = { std::min<vtkIdType>(count[0] - 2, range[1] - lower[0]), std::min<vtkIdType>(count[1] - 2, range[3] - lower[1]) };
    for (vtkIdType j = first[1]; j <= last[1]; ++j)
    {
      if (first[0] <= last[0])
      {
        std::fill(reached.begin() + j * count[0] + first[0], reached.begin() + j * count[0] + last[0] + 1, uint8_t(1));
      }
    }
  }

  vtkNew<vtkFloatArray> distances;
  distances->SetName("SignedDistance");
  distances->SetNumberOfValues(count[0] * count[1]);
  float* values = distances->GetPointer(0);
  const float uncut = static_cast<float>(field->GetBandWidth());
  // No sample exactly on the level: contours then never pass through grid
  // points, so their loops share no vertex.
  const float justOutside = static_cast<float>(1e-6 * finest);
  // GetSignedDistance is safe for concurrent readers.
  vtkSMPTools::For(0, count[1],
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType j = begin; j < end; ++j)
      {
        for (vtkIdType i = 0; i < count[0]; ++i)
        {
          const vtkIdType index = j * count[0] + i;
          if (!reached[index])
          {
            values[index] = uncut;
            continue;
          }
          double ras[3];
          plane.ToRAS((lower[0] + i) * step[0], (lower[1] + j) * step[1], ras);
          const float distance = static_cast<float>(field->GetSignedDistance(ras));
          values[index] = distance == 0.0f ? justOutside : distance;
        }
      }
    });

  result.Image = vtkSmartPointer<vtkImageData>::New();
  result.Image->SetDimensions(static_cast<int>(count[0]), static_cast<int>(count[1]), 1);
  result.Image->SetOrigin(lower[0] * step[0], lower[1] * step[1], 0.0);
  result.Image->SetSpacing(step[0], step[1], 1.0);
  result.Image->GetPointData()->SetScalars(distances);
  result.Spacing = spacing;
  result.Evaluated = static_cast<vtkIdType>(std::count(reached.begin(), reached.end(), uint8_t(1)));
  return result;
}
/// The removed part of the sampled plane (samples below 0) as convex
/// polygons: each run of cells wholly inside as one rectangle, and in each
/// cell the level crosses, the inside part bounded by the crossings that
/// vtkFlyingEdges2D interpolates on the cell's edges, so fill and outline
/// meet. Cost follows the rows and the outline's length, not the area.
/// A saddle cell joins its two inside corners when the cell's mean is inside.
void FillRemovedCells(vtkImageData* samples, vtkPolyData* fill)
{
  const int* dimensions = samples->GetDimensions();
  const double* origin = samples->GetOrigin();
  const double* spacing = samples->GetSpacing();
  const float* values = vtkFloatArray::SafeDownCast(samples->GetPointData()->GetScalars())->GetPointer(0);
  const vtkIdType rowLength = dimensions[0];
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> polygons;
  std::vector<vtkIdType> polygon;
  auto addPoint = [&](double i, double j) { polygon.push_back(points->InsertNextPoint(origin[0] + i * spacing[0], origin[1] + j * spacing[1], 0.0)); };
  for (int j = 0; j + 1 < dimensions[1]; ++j)
  {
    const float* row = values + j * rowLength;
    int i = 0;
    while (i + 1 < dimensions[0])
    {
      // Corners counter-clockwise from (i, j).
      const int offsets[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
      float corner[4];
      int inside = 0;
      for (int k = 0; k < 4; ++k)
      {
        corner[k] = row[offsets[k][1] * rowLength + i + offsets[k][0]];
        inside |= (corner[k] < 0.0f) << k;
      }
      if (inside == 15)
      {
        const int start = i;
        while (i + 1 < dimensions[0] && row[i + 1] < 0.0f && row[rowLength + i + 1] < 0.0f)
        {
          ++i;
        }
        polygon.clear();
        addPoint(start, j);
        addPoint(i, j);
        addPoint(i, j + 1);
        addPoint(start, j + 1);
        polygons->InsertNextCell(static_cast<vtkIdType>(polygon.size()), polygon.data());
        continue;
      }
      auto addCrossing = [&](int from, int to)
      {
        const double t = corner[from] / (static_cast<double>(corner[from]) - corner[to]);
        addPoint(i + offsets[from][0] + t * (offsets[to][0] - offsets[from][0]), j + offsets[from][1] + t * (offsets[to][1] - offsets[from][1]));
      };
      const bool apart = (inside == 5 || inside == 10) && (corner[0] + corner[1] + corner[2] + corner[3]) >= 0.0f;
      if (apart)
      {
        for (int k = 0; k < 4; ++k)
        {
          if (corner[k] < 0.0f)
          {
            polygon.clear();
            addCrossing((k + 3) % 4, k);
            addPoint(i + offsets[k][0], j + offsets[k][1]);
            addCrossing(k, (k + 1) % 4);
            polygons->InsertNextCell(static_cast<vtkIdType>(polygon.size()), polygon.data());
          }
        }
      }
      else if (inside != 0)
      {
        polygon.clear();
        for (int k = 0; k < 4; ++k)
        {
          const int next = (k + 1) % 4;
          if (corner[k] < 0.0f)
          {
            addPoint(i + offsets[k][0], j + offsets[k][1]);
          }
          if ((corner[k] < 0.0f) != (corner[next] < 0.0f))
          {
            addCrossing(k, next);
          }
        }
        polygons->InsertNextCell(static_cast<vtkIdType>(polygon.size()), polygon.data());
      }
      ++i;
    }
  }
  fill->Initialize();
  fill->SetPoints(points);
  fill->SetPolys(polygons);
}
} // namespace

//---------------------------------------------------------------------------
struct vtkMRMLVolumeCutSliceDisplayableManager::Internals
{
  /// What a sampling depended on: when none of it changed, neither did the drawing.
  struct SamplingKey
  {
    vtkVolumeCutField* Field = nullptr;
    vtkMTimeType FieldTime = 0;
    vtkTypeUInt64 Stamp = 0;
    std::array<double, 16> XYToRAS{};
    std::array<int, 2> Dimensions{};
    double OutlineThickness = 0.0;
    bool OutlineShown = false;
    bool FillShown = false;

    bool operator==(const SamplingKey& other) const
    {
      return this->Field == other.Field && this->FieldTime == other.FieldTime && this->Stamp == other.Stamp && this->XYToRAS == other.XYToRAS
        && this->Dimensions == other.Dimensions && this->OutlineThickness == other.OutlineThickness && this->OutlineShown == other.OutlineShown && this->FillShown == other.FillShown;
    }
  };

  struct Pipeline
  {
    vtkSmartPointer<vtkPolyData> Outline;
    vtkSmartPointer<vtkPolyData> Fill;
    vtkSmartPointer<vtkActor2D> OutlineActor;
    vtkSmartPointer<vtkActor2D> FillActor;
    SamplingKey Key;
    bool Sampled = false;
    double SampleSpacing = 0.0;
    vtkIdType NumberOfSamples = 0;
  };

  std::map<vtkMRMLVolumeCutNode*, Pipeline> Pipelines;
  vtkWeakPointer<vtkRenderer> ObservedRenderer;

  Pipeline* Find(vtkMRMLVolumeCutNode* cutNode)
  {
    auto found = this->Pipelines.find(cutNode);
    return found == this->Pipelines.end() ? nullptr : &found->second;
  }
  unsigned long RenderObserverTag = 0;
  bool WarnedCoarseSampling = false;
};

//---------------------------------------------------------------------------
vtkMRMLVolumeCutSliceDisplayableManager::vtkMRMLVolumeCutSliceDisplayableManager()
  : Impl(new Internals)
{
}

//---------------------------------------------------------------------------
vtkMRMLVolumeCutSliceDisplayableManager::~vtkMRMLVolumeCutSliceDisplayableManager()
{
  if (this->Impl->ObservedRenderer)
  {
    this->Impl->ObservedRenderer->RemoveObserver(this->Impl->RenderObserverTag);
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Cut nodes shown: " << this->Impl->Pipelines.size() << "\n";
  os << indent << "MaximumNumberOfSamples: " << this->MaximumNumberOfSamples << "\n";
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::AdditionalInitializeStep()
{
  vtkRenderer* renderer = this->GetRenderer();
  if (renderer == this->Impl->ObservedRenderer)
  {
    return;
  }
  if (this->Impl->ObservedRenderer)
  {
    this->Impl->ObservedRenderer->RemoveObserver(this->Impl->RenderObserverTag);
  }
  this->Impl->ObservedRenderer = renderer;
  if (renderer)
  {
    this->Impl->RenderObserverTag = renderer->AddObserver(vtkCommand::StartEvent, this, &vtkMRMLVolumeCutSliceDisplayableManager::OnRenderStart);
  }
  // Nodes added before the view had a renderer get their actors now.
  this->UpdateFromMRMLScene();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::SetMRMLSceneInternal(vtkMRMLScene* newScene)
{
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkMRMLScene::NodeAddedEvent);
  events->InsertNextValue(vtkMRMLScene::NodeRemovedEvent);
  events->InsertNextValue(vtkMRMLScene::EndCloseEvent);
  events->InsertNextValue(vtkMRMLScene::EndBatchProcessEvent);
  this->SetAndObserveMRMLSceneEventsInternal(newScene, events);
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::OnMRMLSceneNodeAdded(vtkMRMLNode* node)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(node);
  if (!cutNode || this->GetMRMLScene()->IsBatchProcessing())
  {
    return;
  }
  this->UpdateFromMRMLScene();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::OnMRMLSceneNodeRemoved(vtkMRMLNode* node)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(node);
  if (!cutNode)
  {
    return;
  }
  vtkUnObserveMRMLNodeMacro(cutNode);
  auto found = this->Impl->Pipelines.find(cutNode);
  if (found == this->Impl->Pipelines.end())
  {
    return;
  }
  if (vtkRenderer* renderer = this->GetRenderer())
  {
    renderer->RemoveViewProp(found->second.FillActor);
    renderer->RemoveViewProp(found->second.OutlineActor);
  }
  this->Impl->Pipelines.erase(found);
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::OnMRMLSceneEndClose()
{
  vtkRenderer* renderer = this->GetRenderer();
  for (auto& entry : this->Impl->Pipelines)
  {
    if (renderer)
    {
      renderer->RemoveViewProp(entry.second.FillActor);
      renderer->RemoveViewProp(entry.second.OutlineActor);
    }
  }
  this->Impl->Pipelines.clear();
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::UpdateFromMRMLScene()
{
  vtkMRMLScene* scene = this->GetMRMLScene();
  vtkRenderer* renderer = this->GetRenderer();
  if (!scene || !renderer)
  {
    return;
  }
  std::vector<vtkMRMLNode*> nodes;
  scene->GetNodesByClass("vtkMRMLVolumeCutNode", nodes);
  for (vtkMRMLNode* node : nodes)
  {
    vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(node);
    if (!cutNode || this->Impl->Pipelines.count(cutNode))
    {
      continue;
    }
    vtkNew<vtkIntArray> events;
    events->InsertNextValue(vtkCommand::ModifiedEvent);
    events->InsertNextValue(vtkMRMLVolumeCutNode::InputDataModifiedEvent);
    events->InsertNextValue(vtkMRMLVolumeCutNode::CutModifiedEvent);
    vtkObserveMRMLNodeEventsMacro(cutNode, events);

    Internals::Pipeline& pipeline = this->Impl->Pipelines[cutNode];
    pipeline.Outline = vtkSmartPointer<vtkPolyData>::New();
    pipeline.Fill = vtkSmartPointer<vtkPolyData>::New();
    pipeline.OutlineActor = vtkSmartPointer<vtkActor2D>::New();
    pipeline.FillActor = vtkSmartPointer<vtkActor2D>::New();
    const std::pair<vtkActor2D*, vtkPolyData*> layers[2] = { { pipeline.FillActor, pipeline.Fill }, { pipeline.OutlineActor, pipeline.Outline } };
    for (int layer = 0; layer < 2; ++layer)
    {
      vtkActor2D* actor = layers[layer].first;
      vtkNew<vtkPolyDataMapper2D> mapper;
      mapper->SetInputData(layers[layer].second);
      // The polydata carry distances, which are not colours.
      mapper->ScalarVisibilityOff();
      actor->SetMapper(mapper);
      actor->SetVisibility(false);
      actor->SetPickable(false);
      // The outline stays sharp over the translucent fill.
      actor->SetLayerNumber(layer);
      renderer->AddViewProp(actor);
    }
  }
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::ProcessMRMLNodesEvents(vtkObject* caller, unsigned long event, void* callData)
{
  if (vtkMRMLVolumeCutNode::SafeDownCast(caller))
  {
    // Resampling waits for the frame (OnRenderStart): strokes arrive far
    // faster than a view draws.
    this->RequestRender();
    return;
  }
  this->Superclass::ProcessMRMLNodesEvents(caller, event, callData);
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::OnMRMLSliceNodeModifiedEvent()
{
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::OnRenderStart()
{
  for (auto& entry : this->Impl->Pipelines)
  {
    this->UpdatePipeline(entry.first);
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutSliceDisplayableManager::UpdatePipeline(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* found = this->Impl->Find(cutNode);
  if (!found)
  {
    return;
  }
  Internals::Pipeline& pipeline = *found;
  vtkMRMLSliceNode* sliceNode = this->GetMRMLSliceNode();
  vtkVolumeCutField* field = cutNode->GetCutField();

  Internals::SamplingKey key;
  key.Field = field;
  if (field)
  {
    key.FieldTime = field->GetMTime();
    key.Stamp = field->GetCurrentStamp();
  }
  if (sliceNode)
  {
    for (int element = 0; element < 16; ++element)
    {
      key.XYToRAS[element] = sliceNode->GetXYToRAS()->GetElement(element / 4, element % 4);
    }
    key.Dimensions = { sliceNode->GetDimensions()[0], sliceNode->GetDimensions()[1] };
  }
  const bool drawable = field && sliceNode && key.Dimensions[0] > 0 && key.Dimensions[1] > 0;
  key.OutlineThickness = cutNode->GetSliceOutlineThickness();
  key.OutlineShown = drawable && cutNode->GetSliceOutlineVisibility();
  key.FillShown = drawable && cutNode->GetSliceFillVisibility() && cutNode->GetSliceFillOpacity() > 0.0;

  if (!pipeline.Sampled || !(key == pipeline.Key))
  {
    pipeline.Key = key;
    pipeline.Sampled = true;
    pipeline.Outline->Initialize();
    pipeline.Fill->Initialize();
    pipeline.SampleSpacing = 0.0;
    pipeline.NumberOfSamples = 0;
    SlicePlane plane;
    if ((key.OutlineShown || key.FillShown) && plane.Set(sliceNode->GetXYToRAS()))
    {
      // Loops closed along the margin stay out of sight under the thickest line.
      const double marginPixels = 2.0 + 0.5 * key.OutlineThickness;
      const Sampling sampling = SampleSection(field, plane, key.Dimensions.data(), marginPixels, this->MaximumNumberOfSamples);
      if (sampling.Coarsened && !this->Impl->WarnedCoarseSampling)
      {
        vtkWarningMacro("UpdatePipeline: the cut region of '" << (cutNode->GetName() ? cutNode->GetName() : "") << "' in slice view '"
                                                              << (sliceNode->GetName() ? sliceNode->GetName() : "") << "' needs more than "
                                                              << this->MaximumNumberOfSamples << " samples; it is drawn " << sampling.Spacing
                                                              << " mm apart, coarser than the cut field");
        this->Impl->WarnedCoarseSampling = true;
      }
      pipeline.SampleSpacing = sampling.Spacing;
      pipeline.NumberOfSamples = sampling.Evaluated;
      vtkNew<vtkFlyingEdges2D> contour;
      if (sampling.Image)
      {
        contour->SetInputData(sampling.Image);
        contour->SetValue(0, 0.0);
        contour->ComputeScalarsOff();
        contour->Update();
      }
      if (sampling.Image && key.OutlineShown)
      {
        pipeline.Outline->ShallowCopy(contour->GetOutput());
      }
      if (sampling.Image && key.FillShown)
      {
        FillRemovedCells(sampling.Image, pipeline.Fill);
      }
    }
  }

  const double* color = cutNode->GetSliceColor();
  vtkProperty2D* outline = pipeline.OutlineActor->GetProperty();
  outline->SetColor(color[0], color[1], color[2]);
  outline->SetLineWidth(static_cast<float>(cutNode->GetSliceOutlineThickness()));
  outline->SetOpacity(1.0);
  vtkProperty2D* fill = pipeline.FillActor->GetProperty();
  fill->SetColor(color[0], color[1], color[2]);
  fill->SetOpacity(cutNode->GetSliceFillOpacity());
  pipeline.OutlineActor->SetVisibility(key.OutlineShown && pipeline.Outline->GetNumberOfCells() > 0);
  pipeline.FillActor->SetVisibility(key.FillShown && pipeline.Fill->GetNumberOfCells() > 0);
}

//---------------------------------------------------------------------------
vtkPolyData* vtkMRMLVolumeCutSliceDisplayableManager::GetOutline(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* pipeline = this->Impl->Find(cutNode);
  this->UpdatePipeline(cutNode);
  return pipeline ? pipeline->Outline.GetPointer() : nullptr;
}

//---------------------------------------------------------------------------
vtkPolyData* vtkMRMLVolumeCutSliceDisplayableManager::GetFill(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* pipeline = this->Impl->Find(cutNode);
  this->UpdatePipeline(cutNode);
  return pipeline ? pipeline->Fill.GetPointer() : nullptr;
}

//---------------------------------------------------------------------------
vtkActor2D* vtkMRMLVolumeCutSliceDisplayableManager::GetOutlineActor(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* pipeline = this->Impl->Find(cutNode);
  this->UpdatePipeline(cutNode);
  return pipeline ? pipeline->OutlineActor.GetPointer() : nullptr;
}

//---------------------------------------------------------------------------
vtkActor2D* vtkMRMLVolumeCutSliceDisplayableManager::GetFillActor(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* pipeline = this->Impl->Find(cutNode);
  this->UpdatePipeline(cutNode);
  return pipeline ? pipeline->FillActor.GetPointer() : nullptr;
}

//---------------------------------------------------------------------------
double vtkMRMLVolumeCutSliceDisplayableManager::GetSampleSpacing(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* pipeline = this->Impl->Find(cutNode);
  return pipeline ? pipeline->SampleSpacing : 0.0;
}

//---------------------------------------------------------------------------
vtkIdType vtkMRMLVolumeCutSliceDisplayableManager::GetNumberOfSamples(vtkMRMLVolumeCutNode* cutNode)
{
  Internals::Pipeline* pipeline = this->Impl->Find(cutNode);
  return pipeline ? pipeline->NumberOfSamples : 0;
}
