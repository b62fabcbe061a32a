// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutResectionPlanner.h"
#include "vtkVolumeCutDistanceTransform.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkVolumeCutSoftCutThreads.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <unordered_map>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutResectionPlanner);

namespace
{
using Vec = std::array<double, 3>;

Vec Add(const Vec& a, const Vec& b)
{
  return { a[0] + b[0], a[1] + b[1], a[2] + b[2] };
}
Vec Sub(const Vec& a, const Vec& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
Vec Scale(const Vec& a, double s)
{
  return { a[0] * s, a[1] * s, a[2] * s };
}
double Dot(const Vec& a, const Vec& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec Cross(const Vec& a, const Vec& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
double Norm(const Vec& a)
{
  return std::sqrt(Dot(a, a));
}
Vec Normalized(const Vec& a)
{
  const double n = Norm(a);
  return n > 0.0 ? Scale(a, 1.0 / n) : Vec{ 0.0, 0.0, 0.0 };
}

/// Nearest point of segment [a, b] to p, and the squared distance.
double SegmentDistance2(const Vec& p, const Vec& a, const Vec& b, Vec& nearest)
{
  const Vec ab = Sub(b, a);
  const double length2 = Dot(ab, ab);
  double t = length2 > 0.0 ? Dot(Sub(p, a), ab) / length2 : 0.0;
  t = std::min(1.0, std::max(0.0, t));
  nearest = Add(a, Scale(ab, t));
  const Vec d = Sub(p, nearest);
  return Dot(d, d);
}

/// Whether 2D segments [a, b] and [c, d] meet (crossing or touching).
bool SegmentsCross(const double a[2], const double b[2], const double c[2], const double d[2])
{
  auto orient = [](const double p[2], const double q[2], const double r[2]) {
    const double value = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
    return (value > 0.0) - (value < 0.0);
  };
  // r on segment [p, q], given the three are collinear.
  auto within = [](const double p[2], const double q[2], const double r[2]) {
    return std::min(p[0], q[0]) <= r[0] && r[0] <= std::max(p[0], q[0]) && std::min(p[1], q[1]) <= r[1] && r[1] <= std::max(p[1], q[1]);
  };
  const int d1 = orient(c, d, a);
  const int d2 = orient(c, d, b);
  const int d3 = orient(a, b, c);
  const int d4 = orient(a, b, d);
  if (d1 != d2 && d3 != d4 && d1 * d2 <= 0 && d3 * d4 <= 0 && (d1 != 0 || d2 != 0))
  {
    return true;
  }
  return (d1 == 0 && within(c, d, a)) || (d2 == 0 && within(c, d, b)) || (d3 == 0 && within(a, b, c)) || (d4 == 0 && within(a, b, d));
}

template <typename T>
void CopyBox(const T* data, const int dims[3], const int box[6], float* out)
{
  const int size[3] = { box[1] - box[0] + 1, box[3] - box[2] + 1, box[5] - box[4] + 1 };
  vtkVolumeCutSoftCutThreads::For(0, size[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType c = begin; c < end; ++c)
    {
      for (int b = 0; b < size[1]; ++b)
      {
        const T* row = data + ((static_cast<vtkIdType>(box[4] + c) * dims[1] + box[2] + b) * dims[0] + box[0]);
        float* target = out + (static_cast<vtkIdType>(c) * size[1] + b) * size[0];
        for (int a = 0; a < size[0]; ++a)
        {
          target[a] = static_cast<float>(row[a]);
        }
      }
    }
  });
}

std::string FormatPoint(const double ras[3])
{
  std::ostringstream text;
  text.precision(1);
  text << std::fixed << "(" << ras[0] << ", " << ras[1] << ", " << ras[2] << ")";
  return text.str();
}
} // namespace

//------------------------------------------------------------------------------
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

//------------------------------------------------------------------------------
struct vtkVolumeCutResectionPlanner::Internals
{
  // The anatomy's grid: RAS = Origin + Axes * (Spacing .* ijk), Axes orthonormal.
  int Dims[3] = { 0, 0, 0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Axes[3][3];
  double Origin[3] = { 0.0, 0.0, 0.0 };
  vtkDataArray* Scalars = nullptr;

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

  double MinSpacing() const { return std::min({ this->Spacing[0], this->Spacing[1], this->Spacing[2] }); }
  double MaxSpacing() const { return std::max({ this->Spacing[0], this->Spacing[1], this->Spacing[2] }); }

  Vec ToRAS(const Vec& x) const
  {
    Vec ras;
    for (int row = 0; row < 3; ++row)
    {
      ras[row] = this->Origin[row] + this->Axes[row][0] * x[0] + this->Axes[row][1] * x[1] + this->Axes[row][2] * x[2];
    }
    return ras;
  }
  Vec FromRAS(const Vec& ras) const
  {
    const Vec d = { ras[0] - this->Origin[0], ras[1] - this->Origin[1], ras[2] - this->Origin[2] };
    return { this->Axes[0][0] * d[0] + this->Axes[1][0] * d[1] + this->Axes[2][0] * d[2],
      this->Axes[0][1] * d[0] + this->Axes[1][1] * d[1] + this->Axes[2][1] * d[2],
      this->Axes[0][2] * d[0] + this->Axes[1][2] * d[1] + this->Axes[2][2] * d[2] };
  }
  Vec VectorToRAS(const Vec& v) const
  {
    Vec ras;
    for (int row = 0; row < 3; ++row)
    {
      ras[row] = this->Axes[row][0] * v[0] + this->Axes[row][1] * v[1] + this->Axes[row][2] * v[2];
    }
    return ras;
  }

  /// A float copy of the anatomy around the outline, where the outline is
  /// put on the skin and its normals are taken (reading the image's array
  /// through its virtual accessor there would cost more than the shape).
  int LocalBox[6] = { 0, -1, 0, -1, 0, -1 };
  std::vector<float> Local;

  /// CT value of anatomy voxel (i, j, k), clamped to the volume.
  double Voxel(int i, int j, int k) const
  {
    i = std::max(0, std::min(this->Dims[0] - 1, i));
    j = std::max(0, std::min(this->Dims[1] - 1, j));
    k = std::max(0, std::min(this->Dims[2] - 1, k));
    if (i >= this->LocalBox[0] && i <= this->LocalBox[1] && j >= this->LocalBox[2] && j <= this->LocalBox[3] && k >= this->LocalBox[4] &&
      k <= this->LocalBox[5])
    {
      const int sx = this->LocalBox[1] - this->LocalBox[0] + 1;
      const int sy = this->LocalBox[3] - this->LocalBox[2] + 1;
      return this->Local[(static_cast<size_t>(k - this->LocalBox[4]) * sy + (j - this->LocalBox[2])) * sx + (i - this->LocalBox[0])];
    }
    return this->Scalars->GetComponent((static_cast<vtkIdType>(k) * this->Dims[1] + j) * this->Dims[0] + i, 0);
  }

  /// Copies the anatomy's voxels in box (clipped to the volume) into floats: out has the box's size.
  bool CopyVoxels(int box[6], std::vector<float>& out) const
  {
    for (int a = 0; a < 3; ++a)
    {
      box[2 * a] = std::max(0, box[2 * a]);
      box[2 * a + 1] = std::min(this->Dims[a] - 1, box[2 * a + 1]);
      if (box[2 * a + 1] < box[2 * a])
      {
        out.clear();
        return true;
      }
    }
    out.resize(static_cast<size_t>(box[1] - box[0] + 1) * (box[3] - box[2] + 1) * (box[5] - box[4] + 1));
    if (this->Scalars->GetNumberOfComponents() == 1)
    {
      switch (this->Scalars->GetDataType())
      {
        vtkTemplateMacro(CopyBox(static_cast<const VTK_TT*>(this->Scalars->GetVoidPointer(0)), this->Dims, box, out.data()));
        default:
          return false;
      }
      return true;
    }
    size_t index = 0;
    for (int k = box[4]; k <= box[5]; ++k)
    {
      for (int j = box[2]; j <= box[3]; ++j)
      {
        for (int i = box[0]; i <= box[1]; ++i)
        {
          out[index++] = static_cast<float>(this->Scalars->GetComponent((static_cast<vtkIdType>(k) * this->Dims[1] + j) * this->Dims[0] + i, 0));
        }
      }
    }
    return true;
  }

  /// Trilinear CT value at a grid-frame point, from the whole anatomy.
  double Sample(const Vec& x) const
  {
    double index[3];
    int base[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      index[axis] = x[axis] / this->Spacing[axis];
      base[axis] = static_cast<int>(std::floor(index[axis]));
      index[axis] -= base[axis];
    }
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner)
    {
      const int d[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
      const double w = (d[0] ? index[0] : 1.0 - index[0]) * (d[1] ? index[1] : 1.0 - index[1]) * (d[2] ? index[2] : 1.0 - index[2]);
      if (w != 0.0)
      {
        value += w * this->Voxel(base[0] + d[0], base[1] + d[1], base[2] + d[2]);
      }
    }
    return value;
  }

  /// Gradient (HU/mm, grid frame) by central differences one voxel apart.
  Vec Gradient(const Vec& x) const
  {
    Vec g;
    for (int axis = 0; axis < 3; ++axis)
    {
      Vec a = x;
      Vec b = x;
      a[axis] += this->Spacing[axis];
      b[axis] -= this->Spacing[axis];
      g[axis] = (this->Sample(a) - this->Sample(b)) / (2.0 * this->Spacing[axis]);
    }
    return g;
  }

  /**
   * The gradient averaged over the (2r+1)^3 points around x spaced the
   * largest voxel spacing apart along every axis (a cube in mm, so that a
   * curved surface's normal is not tilted towards the finer axes): the sum of
   * their central differences telescopes to the layers r and r + 1 steps away
   * on either side.
   */
  Vec BoxGradient(const Vec& x, int r) const
  {
    const double h = this->MaxSpacing();
    Vec g{ 0.0, 0.0, 0.0 };
    for (int axis = 0; axis < 3; ++axis)
    {
      const int b = (axis + 1) % 3;
      const int c = (axis + 2) % 3;
      double sum = 0.0;
      for (int ob = -r; ob <= r; ++ob)
      {
        for (int oc = -r; oc <= r; ++oc)
        {
          Vec y = x;
          y[b] += ob * h;
          y[c] += oc * h;
          for (int layer : { r, r + 1 })
          {
            Vec up = y;
            Vec down = y;
            up[axis] += layer * h;
            down[axis] -= layer * h;
            sum += this->Sample(up) - this->Sample(down);
          }
        }
      }
      g[axis] = sum;
    }
    return g;
  }

  /// Trilinear value of the plan's box copy at a grid-frame point (clamped to the box).
  static double BoxSample(const PlanData& plan, const double spacing[3], const Vec& x)
  {
    double f[3];
    int base[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      double index = x[axis] / spacing[axis] - plan.Box[2 * axis];
      index = std::max(0.0, std::min(static_cast<double>(plan.Size[axis] - 1), index));
      base[axis] = std::min(plan.Size[axis] - 2, static_cast<int>(std::floor(index)));
      base[axis] = std::max(0, base[axis]);
      f[axis] = plan.Size[axis] > 1 ? index - base[axis] : 0.0;
    }
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner)
    {
      const int d[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
      const double w = (d[0] ? f[0] : 1.0 - f[0]) * (d[1] ? f[1] : 1.0 - f[1]) * (d[2] ? f[2] : 1.0 - f[2]);
      if (w != 0.0)
      {
        const int a = std::min(plan.Size[0] - 1, base[0] + d[0]);
        const int b = std::min(plan.Size[1] - 1, base[1] + d[1]);
        const int c = std::min(plan.Size[2] - 1, base[2] + d[2]);
        value += w * plan.Values[plan.Index(a, b, c)];
      }
    }
    return value;
  }

  /**
   * The skin point on the line x + t * direction nearest t = 0 within
   * |t| <= reach (mm): where the CT crosses the iso-value. False if none.
   */
  bool FindCrossing(const Vec& x, const Vec& direction, double reach, double iso, Vec& found) const
  {
    const double step = 0.25 * this->MinSpacing();
    const double v0 = this->Sample(x) - iso;
    if (v0 == 0.0)
    {
      found = x;
      return true;
    }
    for (double t = step; t <= reach + 1e-9; t += step)
    {
      for (double sign : { 1.0, -1.0 })
      {
        const Vec y = Add(x, Scale(direction, sign * t));
        const double v = this->Sample(y) - iso;
        if ((v > 0.0) != (v0 > 0.0) || v == 0.0)
        {
          // Bisection between the last two samples.
          double lo = sign * (t - step);
          double hi = sign * t;
          double vLo = this->Sample(Add(x, Scale(direction, lo))) - iso;
          for (int iteration = 0; iteration < 30; ++iteration)
          {
            const double mid = 0.5 * (lo + hi);
            const double vMid = this->Sample(Add(x, Scale(direction, mid))) - iso;
            if ((vMid > 0.0) == (vLo > 0.0))
            {
              lo = mid;
              vLo = vMid;
            }
            else
            {
              hi = mid;
            }
          }
          found = Add(x, Scale(direction, 0.5 * (lo + hi)));
          return true;
        }
      }
    }
    return false;
  }

  /// A closed polyline through grid-frame points, in RAS.
  void MakePolyline(const std::vector<Vec>& points, vtkPolyData* polyline) const
  {
    vtkNew<vtkPoints> ras;
    vtkNew<vtkCellArray> lines;
    lines->InsertNextCell(static_cast<vtkIdType>(points.size()) + 1);
    for (const Vec& point : points)
    {
      const Vec r = this->ToRAS(point);
      lines->InsertCellPoint(ras->InsertNextPoint(r.data()));
    }
    lines->InsertCellPoint(0);
    polyline->SetPoints(ras);
    polyline->SetLines(lines);
  }

  /// One of the current plan's polylines (outline, strips) in RAS; empty without a plan.
  void CopyPolyline(std::vector<Vec> PlanData::*which, vtkPolyData* polyline) const
  {
    if (polyline)
    {
      polyline->Initialize();
      if (this->Current)
      {
        this->MakePolyline(this->Current.get()->*which, polyline);
      }
    }
  }

  /// The current plan, with image emptied and given the box's extent; nullptr without either.
  const PlanData* StartBoxImage(vtkImageData* image) const
  {
    if (!image)
    {
      return nullptr;
    }
    image->Initialize();
    if (!this->Current)
    {
      return nullptr;
    }
    image->SetExtent(const_cast<int*>(this->Current->Box));
    return this->Current.get();
  }

  /// A point onto the skin along the gradient; false if the skin is beyond reach.
  bool ToSkin(const Vec& x, double reach, double iso, Vec& onSkin) const
  {
    Vec direction = Normalized(this->Gradient(x));
    if (Norm(direction) == 0.0)
    {
      return false;
    }
    return this->FindCrossing(x, direction, reach, iso, onSkin);
  }
};

//------------------------------------------------------------------------------
vtkVolumeCutResectionPlanner::vtkVolumeCutResectionPlanner()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkVolumeCutResectionPlanner::~vtkVolumeCutResectionPlanner() = default;

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Fail(const std::string& message) const
{
  this->ErrorMessage = message;
  vtkErrorMacro(<< message);
  return false;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::SetAnatomy(vtkImageData* image, vtkMatrix4x4* ijkToRAS)
{
  this->Anatomy = image;
  if (ijkToRAS)
  {
    this->IJKToRAS = vtkSmartPointer<vtkMatrix4x4>::New();
    this->IJKToRAS->DeepCopy(ijkToRAS);
  }
  else if (image)
  {
    this->IJKToRAS = vtkSmartPointer<vtkMatrix4x4>::New();
    double origin[3];
    double spacing[3];
    image->GetOrigin(origin);
    image->GetSpacing(spacing);
    vtkMatrix3x3* direction = image->GetDirectionMatrix();
    for (int row = 0; row < 3; ++row)
    {
      for (int column = 0; column < 3; ++column)
      {
        this->IJKToRAS->SetElement(row, column, direction->GetElement(row, column) * spacing[column]);
      }
      this->IJKToRAS->SetElement(row, 3, origin[row]);
    }
  }
  else
  {
    this->IJKToRAS = nullptr;
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::SetOutline(vtkPoints* points)
{
  this->Outline = vtkSmartPointer<vtkPoints>::New();
  if (points)
  {
    this->Outline->DeepCopy(points);
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetIJKToRAS(vtkMatrix4x4* matrix) const
{
  if (matrix && this->IJKToRAS)
  {
    matrix->DeepCopy(this->IJKToRAS);
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Plan()
{
  // Each pass grows the faces of the box that the resection reached.
  for (int pass = 0; pass < 6; ++pass)
  {
    if (!this->BuildShape())
    {
      return false;
    }
    const bool* reached = this->Impl->Next->Reached;
    if (std::none_of(reached, reached + 6, [](bool r) { return r; }))
    {
      if (!this->BuildMask())
      {
        return false;
      }
      reached = this->Impl->Current->Reached;
      if (std::none_of(reached, reached + 6, [](bool r) { return r; }))
      {
        return true;
      }
    }
    for (int face = 0; face < 6; ++face)
    {
      if (reached[face])
      {
        const int axis = face / 2;
        this->Impl->Growth[face] += std::max(8, static_cast<int>(std::ceil(0.5 * this->MaximumDepth / this->Impl->Spacing[axis])));
      }
    }
  }
  vtkWarningMacro("Plan: the resection still reaches the bounding box after growing it six times; what lies beyond is left out");
  return !this->Impl->Next || this->BuildMask();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::UpdateGrid(const char* caller)
{
  Internals& impl = *this->Impl;
  const std::string where = std::string(caller) + ": ";
  vtkDataArray* scalars = this->Anatomy ? this->Anatomy->GetPointData()->GetScalars() : nullptr;
  if (!this->Anatomy || !this->IJKToRAS || !scalars)
  {
    return this->Fail(where + "no CT with scalars; give the planner the CT with SetAnatomy");
  }
  int dims[3];
  this->Anatomy->GetDimensions(dims);
  const int* extent = this->Anatomy->GetExtent();
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2 || extent[0] != 0 || extent[2] != 0 || extent[4] != 0)
  {
    return this->Fail(where + "the CT must have at least 2 voxels along each axis and an extent starting at 0");
  }
  double spacing[3];
  double axes[3][3];
  for (int column = 0; column < 3; ++column)
  {
    Vec axis;
    for (int row = 0; row < 3; ++row)
    {
      axis[row] = this->IJKToRAS->GetElement(row, column);
    }
    spacing[column] = Norm(axis);
    if (!(spacing[column] > 0.0) || !std::isfinite(spacing[column]))
    {
      return this->Fail(where + "the CT's IJK-to-RAS matrix has a zero or non-finite spacing");
    }
    for (int row = 0; row < 3; ++row)
    {
      axes[row][column] = axis[row] / spacing[column];
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    for (int b = a + 1; b < 3; ++b)
    {
      if (std::abs(axes[0][a] * axes[0][b] + axes[1][a] * axes[1][b] + axes[2][a] * axes[2][b]) > 1e-3)
      {
        return this->Fail(where + "the CT's voxel axes are not orthogonal (a sheared grid); resample it onto an orthogonal grid first");
      }
    }
  }
  std::copy(dims, dims + 3, impl.Dims);
  std::copy(spacing, spacing + 3, impl.Spacing);
  for (int row = 0; row < 3; ++row)
  {
    std::copy(axes[row], axes[row] + 3, impl.Axes[row]);
    impl.Origin[row] = this->IJKToRAS->GetElement(row, 3);
  }
  // The local copy is made again for each outline (the CT may have changed).
  impl.LocalBox[0] = impl.LocalBox[2] = impl.LocalBox[4] = 0;
  impl.LocalBox[1] = impl.LocalBox[3] = impl.LocalBox[5] = -1;
  impl.Scalars = scalars;
  return true;
}

//------------------------------------------------------------------------------
double vtkVolumeCutResectionPlanner::GetDistanceToSkin(const double ras[3], double reach)
{
  if (!ras || !this->UpdateGrid("GetDistanceToSkin"))
  {
    return VTK_DOUBLE_MAX;
  }
  const Vec x = this->Impl->FromRAS({ ras[0], ras[1], ras[2] });
  Vec onSkin;
  if (!this->Impl->ToSkin(x, reach, this->SkinIsoValue, onSkin))
  {
    return VTK_DOUBLE_MAX;
  }
  return Norm(Sub(onSkin, x));
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildShape()
{
  Internals& impl = *this->Impl;
  this->ErrorMessage.clear();
  if (!this->UpdateGrid("BuildShape"))
  {
    return false;
  }
  const int* dims = impl.Dims;
  const double* spacing = impl.Spacing;
  if (this->GetMTime() != impl.GrowthTime)
  {
    std::fill(impl.Growth, impl.Growth + 6, 0);
    impl.GrowthTime = this->GetMTime();
  }
  if (!(this->SoftTissueRange[0] <= this->SoftTissueRange[1]))
  {
    return this->Fail("BuildShape: the soft-tissue range is empty (its minimum is above its maximum)");
  }
  if (!(this->MaximumDepth > 0.0))
  {
    return this->Fail("BuildShape: the maximum depth must be positive");
  }
  const double diagonal = std::sqrt(std::pow(dims[0] * spacing[0], 2) + std::pow(dims[1] * spacing[1], 2) + std::pow(dims[2] * spacing[2], 2));
  if (this->MaximumDepth > diagonal)
  {
    std::ostringstream text;
    text << "BuildShape: the maximum depth " << this->MaximumDepth << " mm goes beyond the CT (" << diagonal << " mm across)";
    return this->Fail(text.str());
  }

  // 1. The outline, on the skin.
  std::vector<Vec> given;
  const vtkIdType count = this->Outline ? this->Outline->GetNumberOfPoints() : 0;
  for (vtkIdType id = 0; id < count; ++id)
  {
    double ras[3];
    this->Outline->GetPoint(id, ras);
    if (!std::isfinite(ras[0]) || !std::isfinite(ras[1]) || !std::isfinite(ras[2]))
    {
      return this->Fail("BuildShape: outline point " + std::to_string(id) + " is not finite");
    }
    const Vec x = impl.FromRAS({ ras[0], ras[1], ras[2] });
    if (given.empty() || Norm(Sub(x, given.back())) > 1e-6)
    {
      given.push_back(x);
    }
  }
  while (given.size() > 1 && Norm(Sub(given.front(), given.back())) <= 1e-6)
  {
    given.pop_back();
  }
  if (given.size() < 3)
  {
    return this->Fail("BuildShape: the outline has " + std::to_string(given.size()) +
      " distinct point(s); a closed outline on the skin needs at least 3");
  }
  const double iso = this->SkinIsoValue;
  {
    // Everything the outline's points and normals read: the points' box
    // grown by the search reach and the normals' stencil.
    double lowest[3] = { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity() };
    double highest[3] = { -lowest[0], -lowest[1], -lowest[2] };
    for (const Vec& x : given)
    {
      for (int a = 0; a < 3; ++a)
      {
        lowest[a] = std::min(lowest[a], x[a] / spacing[a]);
        highest[a] = std::max(highest[a], x[a] / spacing[a]);
      }
    }
    const double searchReach = std::max(this->SkinTolerance, 3.0 * std::max({ spacing[0], spacing[1], spacing[2] }));
    impl.LocalBox[0] = impl.LocalBox[2] = impl.LocalBox[4] = 0;
    impl.LocalBox[1] = impl.LocalBox[3] = impl.LocalBox[5] = -1;
    int local[6];
    for (int a = 0; a < 3; ++a)
    {
      const int pad = 2 + static_cast<int>(std::ceil((searchReach + 3.0 * std::max({ spacing[0], spacing[1], spacing[2] })) / spacing[a]));
      local[2 * a] = static_cast<int>(std::floor(lowest[a])) - pad;
      local[2 * a + 1] = static_cast<int>(std::ceil(highest[a])) + pad;
    }
    std::vector<float> values;
    if (!impl.CopyVoxels(local, values))
    {
      return this->Fail("BuildShape: the CT's scalar type is not supported");
    }
    impl.Local.swap(values);
    std::copy(local, local + 6, impl.LocalBox);
  }
  for (size_t k = 0; k < given.size(); ++k)
  {
    const Vec ras = impl.ToRAS(given[k]);
    bool inside = true;
    for (int axis = 0; axis < 3; ++axis)
    {
      const double index = given[k][axis] / spacing[axis];
      inside &= index >= -0.5 && index <= dims[axis] - 0.5;
    }
    if (!inside)
    {
      return this->Fail("BuildShape: outline point " + std::to_string(k) + " at RAS " + FormatPoint(ras.data()) + " lies outside the CT");
    }
    Vec onSkin;
    if (!impl.ToSkin(given[k], this->SkinTolerance, iso, onSkin))
    {
      std::ostringstream text;
      text << "BuildShape: outline point " << k << " at RAS " << FormatPoint(ras.data()) << " is more than " << this->SkinTolerance
           << " mm from the skin (the CT's " << iso << " HU iso-surface); place the outline on the skin";
      return this->Fail(text.str());
    }
  }
  // Resampled evenly, half the smallest spacing apart, and put on the skin.
  std::vector<double> arc(given.size() + 1, 0.0);
  for (size_t k = 0; k < given.size(); ++k)
  {
    arc[k + 1] = arc[k] + Norm(Sub(given[(k + 1) % given.size()], given[k]));
  }
  const double total = arc.back();
  const int samples = static_cast<int>(std::min(20000.0, std::max(static_cast<double>(given.size()), std::ceil(total / (0.5 * impl.MinSpacing())))));
  if (impl.Next)
  {
    impl.Spare = std::move(impl.Next);
  }
  auto plan = impl.NewPlan();
  plan->Points.resize(samples);
  const double reach = std::max(this->SkinTolerance, 3.0 * impl.MaxSpacing());
  size_t segment = 0;
  for (int k = 0; k < samples; ++k)
  {
    const double s = total * k / samples;
    while (segment + 1 < given.size() && arc[segment + 1] <= s)
    {
      ++segment;
    }
    const double length = arc[segment + 1] - arc[segment];
    const double t = length > 0.0 ? (s - arc[segment]) / length : 0.0;
    const Vec x = Add(given[segment], Scale(Sub(given[(segment + 1) % given.size()], given[segment]), t));
    if (!impl.ToSkin(x, reach, iso, plan->Points[k]))
    {
      std::ostringstream text;
      text << "BuildShape: the outline between points " << segment << " and " << (segment + 1) % given.size() << " leaves the skin by more than "
           << reach << " mm near RAS " << FormatPoint(impl.ToRAS(x).data()) << "; add points on the skin there";
      return this->Fail(text.str());
    }
  }
  const int n = samples;
  const double step = total / samples;
  plan->Length = 0.0;
  for (int k = 0; k < n; ++k)
  {
    plan->Length += Norm(Sub(plan->Points[(k + 1) % n], plan->Points[k]));
  }

  // 2. Normals (outward: the inverse gradient). A sharp skin edge sampled
  // by trilinear interpolation has terraces whose gradients tilt by several
  // degrees, which would tilt the wall: the gradient is averaged over a box
  // of five voxels, at points about two voxels apart along the outline, then
  // smoothed along the outline over two voxels on either side.
  std::vector<Vec> local(n);
  {
    const int stride = std::max(1, static_cast<int>(std::lround(2.0 * impl.MinSpacing() / step)));
    std::vector<int> at;
    for (int k = 0; k < n; k += stride)
    {
      at.push_back(k);
    }
    std::vector<Vec> sampled(at.size());
    vtkVolumeCutSoftCutThreads::For(0, static_cast<vtkIdType>(at.size()), [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType m = begin; m < end; ++m)
      {
        sampled[m] = Normalized(Scale(impl.BoxGradient(plan->Points[at[m]], 2), -1.0));
      }
    });
    for (size_t m = 0; m < at.size(); ++m)
    {
      const int first = at[m];
      const int last = m + 1 < at.size() ? at[m + 1] : n;
      const Vec& a = sampled[m];
      const Vec& b = sampled[(m + 1) % at.size()];
      for (int k = first; k < last; ++k)
      {
        const double t = double(k - first) / (last - first);
        local[k] = Normalized(Add(Scale(a, 1.0 - t), Scale(b, t)));
      }
    }
  }
  const int window = std::max(1, static_cast<int>(std::lround(2.0 * impl.MaxSpacing() / step)));
  plan->Normals.resize(n);
  Vec sum{ 0.0, 0.0, 0.0 };
  for (int k = 0; k < n; ++k)
  {
    Vec smoothed{ 0.0, 0.0, 0.0 };
    for (int offset = -window; offset <= window; ++offset)
    {
      smoothed = Add(smoothed, local[((k + offset) % n + n) % n]);
    }
    plan->Normals[k] = Normalized(smoothed);
    sum = Add(sum, local[k]);
  }
  if (Norm(sum) < 0.2 * n)
  {
    return this->Fail("BuildShape: the outline's skin normals cancel out (is it drawn around the head or a limb?); draw it on one side of the surface");
  }
  plan->AverageNormal = Normalized(sum);

  // Seen along the average normal: orientation, area, crossings.
  const Vec& axis = plan->AverageNormal;
  Vec helper = std::abs(axis[0]) < 0.9 ? Vec{ 1.0, 0.0, 0.0 } : Vec{ 0.0, 1.0, 0.0 };
  const Vec e1 = Normalized(Cross(axis, helper));
  const Vec e2 = Cross(axis, e1);
  std::vector<std::array<double, 2>> flat(n);
  for (int k = 0; k < n; ++k)
  {
    flat[k] = { Dot(plan->Points[k], e1), Dot(plan->Points[k], e2) };
  }
  double area = 0.0;
  for (int k = 0; k < n; ++k)
  {
    const auto& a = flat[k];
    const auto& b = flat[(k + 1) % n];
    area += 0.5 * (a[0] * b[1] - b[0] * a[1]);
  }
  {
    const int stride = std::max(1, n / 512);
    std::vector<int> kept;
    for (int k = 0; k < n; k += stride)
    {
      kept.push_back(k);
    }
    const int m = static_cast<int>(kept.size());
    for (int a = 0; a < m; ++a)
    {
      for (int b = a + 2; b < m; ++b)
      {
        if (a == 0 && b == m - 1)
        {
          continue;
        }
        if (SegmentsCross(flat[kept[a]].data(), flat[kept[(a + 1) % m]].data(), flat[kept[b]].data(), flat[kept[(b + 1) % m]].data()))
        {
          return this->Fail("BuildShape: the outline crosses itself near RAS " + FormatPoint(impl.ToRAS(plan->Points[kept[a]]).data()) +
            "; draw a simple closed curve");
        }
      }
    }
  }

  plan->Area = std::abs(area);
  if (plan->Area < impl.MinSpacing() * impl.MinSpacing())
  {
    return this->Fail("BuildShape: the outline encloses no area seen along its normal; draw a closed curve around the region to resect");
  }
  // Strips: each point offset in the tangent plane, perpendicular to the
  // outline, towards the inside (counter-clockwise seen from outside: left).
  const double delta = this->StripOffset > 0.0 ? this->StripOffset : 2.0 * impl.MaxSpacing();
  const double orientation = area > 0.0 ? 1.0 : -1.0;
  const int reachOfTangent = std::max(1, static_cast<int>(std::lround(impl.MaxSpacing() / step)));
  plan->Inner.resize(n);
  plan->Outer.resize(n);
  std::vector<Vec> inward(n);
  Vec previous{ 0.0, 0.0, 0.0 };
  for (int k = 0; k < n; ++k)
  {
    const Vec tangent = Normalized(Sub(plan->Points[(k + reachOfTangent) % n], plan->Points[((k - reachOfTangent) % n + n) % n]));
    const Vec& normal = this->NormalMode == LocalNormal ? plan->Normals[k] : plan->AverageNormal;
    Vec w = Cross(normal, tangent);
    w = Norm(w) > 1e-6 ? Scale(Normalized(w), orientation) : previous;
    previous = w;
    inward[k] = w;
    plan->Inner[k] = Add(plan->Points[k], Scale(w, delta));
    plan->Outer[k] = Sub(plan->Points[k], Scale(w, delta));
  }

  // 3. The box: strips, the outline moved the maximum depth in, a margin.
  double lower[3] = { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity() };
  double upper[3] = { -lower[0], -lower[1], -lower[2] };
  auto include = [&](const Vec& x) {
    for (int a = 0; a < 3; ++a)
    {
      lower[a] = std::min(lower[a], x[a] / spacing[a]);
      upper[a] = std::max(upper[a], x[a] / spacing[a]);
    }
  };
  Vec centroid{ 0.0, 0.0, 0.0 };
  for (int k = 0; k < n; ++k)
  {
    const Vec& normal = this->NormalMode == LocalNormal ? plan->Normals[k] : plan->AverageNormal;
    include(plan->Inner[k]);
    include(plan->Outer[k]);
    include(Sub(plan->Points[k], Scale(normal, this->MaximumDepth)));
    include(Add(plan->Points[k], Scale(normal, 2.0 * impl.MaxSpacing())));
    centroid = Add(centroid, Scale(plan->Points[k], 1.0 / n));
  }
  include(Sub(centroid, Scale(plan->AverageNormal, this->MaximumDepth)));
  const int margin = 3 + static_cast<int>(std::ceil(delta / impl.MinSpacing()));
  for (int a = 0; a < 3; ++a)
  {
    plan->Box[2 * a] = std::max(0, static_cast<int>(std::floor(lower[a])) - margin - impl.Growth[2 * a]);
    plan->Box[2 * a + 1] = std::min(dims[a] - 1, static_cast<int>(std::ceil(upper[a])) + margin + impl.Growth[2 * a + 1]);
    plan->Size[a] = plan->Box[2 * a + 1] - plan->Box[2 * a] + 1;
    if (plan->Size[a] < 2)
    {
      return this->Fail("BuildShape: the outline lies outside the CT");
    }
  }
  const double voxels = double(plan->Size[0]) * plan->Size[1] * plan->Size[2];
  if (voxels > 1.5e9)
  {
    return this->Fail("BuildShape: the resection's bounding box is too large (" + std::to_string(static_cast<long long>(voxels)) +
      " voxels); draw a smaller outline or lower the maximum depth");
  }
  PlanData& p = *plan;
  p.Count = static_cast<vtkIdType>(voxels);
  const vtkIdType N = p.Count;
  {
    int box[6];
    std::copy(p.Box, p.Box + 6, box);
    impl.CopyVoxels(box, p.Values);
  }

  // One exact distance transform towards both strips: a voxel is in the
  // shape when its nearest strip site lies on the inner strip (the paper's
  // two transforms and their comparison, in one pass).
  std::vector<unsigned char>& sites = impl.Sites;
  sites.assign(N, 0);
  std::vector<int>& onStrip = impl.Scratch; // read only at sites: 1 inner, 2 outer
  onStrip.resize(N);
  p.StripSites.clear();
  for (int which = 1; which <= 2; ++which)
  {
    const std::vector<Vec>& strip = which == 1 ? p.Inner : p.Outer;
    for (int k = 0; k < n; ++k)
    {
      const Vec& a = strip[k];
      const Vec& b = strip[(k + 1) % n];
      const int steps = 1 + static_cast<int>(std::ceil(Norm(Sub(b, a)) / (0.25 * impl.MinSpacing())));
      for (int s = 0; s <= steps; ++s)
      {
        const Vec x = Add(a, Scale(Sub(b, a), double(s) / steps));
        int index[3];
        bool inside = true;
        for (int axisIndex = 0; axisIndex < 3; ++axisIndex)
        {
          index[axisIndex] = static_cast<int>(std::lround(x[axisIndex] / spacing[axisIndex])) - p.Box[2 * axisIndex];
          inside &= index[axisIndex] >= 0 && index[axisIndex] < p.Size[axisIndex];
        }
        if (inside)
        {
          const vtkIdType id = p.Index(index[0], index[1], index[2]);
          if (!sites[id])
          {
            sites[id] = 1;
            onStrip[id] = which;
            p.StripSites.emplace(static_cast<int>(id), k);
          }
        }
      }
    }
  }
  p.Feature.resize(N);
  impl.Work.resize(N);
  vtkVolumeCutDistanceTransform::Compute(p.Size, spacing, sites.data(), impl.Work.data(), p.Feature.data());
  p.Class.resize(N);
  vtkVolumeCutSoftCutThreads::For(0, N, [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType id = begin; id < end; ++id)
    {
      const int site = p.Feature[id];
      p.Class[id] = site >= 0 && onStrip[site] == 1 ? vtkVolumeCutResectionPlanner::InShape : 0;
    }
  });

  // The skin inside the outline: tissue voxels next to air, connected
  // (26-neighbours) to the skin just inside the outline.
  const float isoValue = static_cast<float>(iso);
  auto isSkin = [&](int a, int b, int c) {
    const vtkIdType id = p.Index(a, b, c);
    if (!(p.Class[id] & InShape) || !(p.Values[id] >= isoValue) || (p.Class[id] & SkinPatch))
    {
      return false;
    }
    const int neighbour[6][3] = { { -1, 0, 0 }, { 1, 0, 0 }, { 0, -1, 0 }, { 0, 1, 0 }, { 0, 0, -1 }, { 0, 0, 1 } };
    for (const auto& d : neighbour)
    {
      const int q[3] = { a + d[0], b + d[1], c + d[2] };
      if (q[0] >= 0 && q[1] >= 0 && q[2] >= 0 && q[0] < p.Size[0] && q[1] < p.Size[1] && q[2] < p.Size[2] &&
        p.Values[p.Index(q[0], q[1], q[2])] < isoValue)
      {
        return true;
      }
    }
    return false;
  };
  std::vector<vtkIdType> stack;
  const int seedStride = std::max(1, n / 256);
  for (int k = 0; k < n; k += seedStride)
  {
    const Vec y = Add(plan->Points[k], Scale(inward[k], 0.5 * delta));
    int center[3];
    for (int a = 0; a < 3; ++a)
    {
      center[a] = static_cast<int>(std::lround(y[a] / spacing[a])) - p.Box[2 * a];
    }
    double best = std::numeric_limits<double>::infinity();
    vtkIdType bestId = -1;
    for (int dc = -2; dc <= 2; ++dc)
    {
      for (int db = -2; db <= 2; ++db)
      {
        for (int da = -2; da <= 2; ++da)
        {
          const int q[3] = { center[0] + da, center[1] + db, center[2] + dc };
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= p.Size[0] || q[1] >= p.Size[1] || q[2] >= p.Size[2] || !isSkin(q[0], q[1], q[2]))
          {
            continue;
          }
          const Vec x = { (p.Box[0] + q[0]) * spacing[0], (p.Box[2] + q[1]) * spacing[1], (p.Box[4] + q[2]) * spacing[2] };
          const double d = Norm(Sub(x, y));
          if (d < best)
          {
            best = d;
            bestId = p.Index(q[0], q[1], q[2]);
          }
        }
      }
    }
    if (bestId >= 0 && !(p.Class[bestId] & SkinPatch))
    {
      p.Class[bestId] |= SkinPatch;
      stack.push_back(bestId);
      p.Skin.push_back(bestId);
    }
  }
  if (stack.empty())
  {
    return this->Fail("BuildShape: no skin (CT values above the " + std::to_string(static_cast<int>(iso)) +
      " HU iso-value next to air) was found inside the outline; check the skin iso-value for this CT");
  }
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];
  while (!stack.empty())
  {
    const vtkIdType id = stack.back();
    stack.pop_back();
    const int a = static_cast<int>(id % sx);
    const int b = static_cast<int>((id / sx) % p.Size[1]);
    const int c = static_cast<int>(id / sxy);
    for (int dc = -1; dc <= 1; ++dc)
    {
      for (int db = -1; db <= 1; ++db)
      {
        for (int da = -1; da <= 1; ++da)
        {
          const int q[3] = { a + da, b + db, c + dc };
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= p.Size[0] || q[1] >= p.Size[1] || q[2] >= p.Size[2] || !isSkin(q[0], q[1], q[2]))
          {
            continue;
          }
          const vtkIdType neighbour = p.Index(q[0], q[1], q[2]);
          p.Class[neighbour] |= SkinPatch;
          stack.push_back(neighbour);
          p.Skin.push_back(neighbour);
        }
      }
    }
  }

  // The flood fill (face neighbours) from the skin through soft tissue in
  // the shape: bone and air stop it.
  const float low = static_cast<float>(this->SoftTissueRange[0]);
  const float high = static_cast<float>(this->SoftTissueRange[1]);
  p.FilledCount = 0;
  for (const vtkIdType id : p.Skin)
  {
    if (p.Values[id] >= low && p.Values[id] <= high)
    {
      p.Class[id] |= FilledTissue;
      stack.push_back(id);
      ++p.FilledCount;
    }
  }
  const vtkIdType faceSteps[6] = { -1, 1, -sx, sx, -sxy, sxy };
  while (!stack.empty())
  {
    const vtkIdType id = stack.back();
    stack.pop_back();
    const int position[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
    for (int face = 0; face < 6; ++face)
    {
      const int axisIndex = face / 2;
      const int moved = position[axisIndex] + ((face & 1) ? 1 : -1);
      if (moved < 0 || moved >= p.Size[axisIndex])
      {
        continue;
      }
      const vtkIdType neighbour = id + faceSteps[face];
      const uint8_t cls = p.Class[neighbour];
      const float value = p.Values[neighbour];
      if ((cls & InShape) && !(cls & FilledTissue) && value >= low && value <= high)
      {
        p.Class[neighbour] = cls | FilledTissue;
        stack.push_back(neighbour);
        ++p.FilledCount;
      }
    }
  }
  for (const vtkIdType id : p.Skin)
  {
    // The skin reaching a face of the box that is not the CT's: grow there.
    const int position[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
    for (int a = 0; a < 3; ++a)
    {
      p.Reached[2 * a] |= position[a] == 0 && p.Box[2 * a] > 0;
      p.Reached[2 * a + 1] |= position[a] == p.Size[a] - 1 && p.Box[2 * a + 1] < dims[a] - 1;
    }
  }
  if (p.FilledCount == 0)
  {
    std::ostringstream text;
    text << "BuildShape: the outline encloses no soft tissue (CT values " << low << " to " << high
         << " HU) under the skin; nothing to resect there";
    return this->Fail(text.str());
  }

  impl.Next = std::move(plan);
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildMask()
{
  Internals& impl = *this->Impl;
  this->ErrorMessage.clear();
  if (!impl.Next)
  {
    return this->Fail("BuildMask: there is no shape to build the mask of; call BuildShape first");
  }
  PlanData& p = *impl.Next;
  const vtkIdType N = p.Count;
  const double* spacing = impl.Spacing;
  const float iso = static_cast<float>(this->SkinIsoValue);

  // The skin's sub-voxel surface near each of its voxels inside the outline:
  // where the CT crosses the iso-value along the gradient, and the inward
  // normal there.
  std::vector<int>& slot = impl.Scratch;
  slot.resize(N);
  const std::vector<vtkIdType>& skin = p.Skin;
  std::vector<unsigned char>& sites = impl.Sites;
  sites.assign(N, 0);
  for (size_t s = 0; s < skin.size(); ++s)
  {
    slot[skin[s]] = static_cast<int>(s);
    sites[skin[s]] = 1;
  }
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];
  auto position = [&](vtkIdType id) {
    return Vec{ (p.Box[0] + static_cast<int>(id % sx)) * spacing[0], (p.Box[2] + static_cast<int>((id / sx) % p.Size[1])) * spacing[1],
      (p.Box[4] + static_cast<int>(id / sxy)) * spacing[2] };
  };
  std::vector<float> surface(6 * skin.size());
  vtkVolumeCutSoftCutThreads::For(0, static_cast<vtkIdType>(skin.size()), [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType s = begin; s < end; ++s)
    {
      const Vec center = position(skin[s]);
      Vec gradient;
      for (int a = 0; a < 3; ++a)
      {
        Vec up = center;
        Vec down = center;
        up[a] += spacing[a];
        down[a] -= spacing[a];
        gradient[a] = (Internals::BoxSample(p, spacing, up) - Internals::BoxSample(p, spacing, down)) / (2.0 * spacing[a]);
      }
      Vec normal = Normalized(gradient);
      Vec point = center;
      if (Norm(normal) > 0.0)
      {
        // The voxel is tissue; air lies against the gradient within two voxels.
        const double stepLength = 0.5 * impl.MinSpacing();
        double previous = 0.0;
        for (double t = stepLength; t <= 2.0 * impl.MaxSpacing() + 1e-9; t += stepLength)
        {
          if (Internals::BoxSample(p, spacing, Sub(center, Scale(normal, t))) < iso)
          {
            double lo = previous;
            double hi = t;
            for (int iteration = 0; iteration < 12; ++iteration)
            {
              const double mid = 0.5 * (lo + hi);
              (Internals::BoxSample(p, spacing, Sub(center, Scale(normal, mid))) < iso ? hi : lo) = mid;
            }
            point = Sub(center, Scale(normal, 0.5 * (lo + hi)));
            break;
          }
          previous = t;
        }
      }
      else
      {
        normal = Scale(p.AverageNormal, -1.0);
      }
      for (int a = 0; a < 3; ++a)
      {
        surface[6 * s + a] = static_cast<float>(point[a]);
        surface[6 * s + 3 + a] = static_cast<float>(normal[a]);
      }
    }
  });

  // The third transform: every voxel's nearest skin voxel, then its depth
  // under that voxel's tangent plane.
  impl.Work.resize(N);
  std::vector<int>& nearest = impl.Nearest;
  nearest.resize(N);
  vtkVolumeCutDistanceTransform::Compute(p.Size, spacing, sites.data(), impl.Work.data(), nearest.data());
  p.Depth.resize(N);
  vtkVolumeCutSoftCutThreads::For(0, p.Size[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType c = begin; c < end; ++c)
    {
      const double z = (p.Box[4] + c) * spacing[2];
      for (int b = 0; b < p.Size[1]; ++b)
      {
        const double y = (p.Box[2] + b) * spacing[1];
        vtkIdType id = p.Index(0, b, static_cast<int>(c));
        for (int a = 0; a < p.Size[0]; ++a, ++id)
        {
          const float* site = &surface[6 * static_cast<size_t>(slot[nearest[id]])];
          const double x = (p.Box[0] + a) * spacing[0];
          p.Depth[id] = static_cast<float>(site[3] * (x - site[0]) + site[4] * (y - site[1]) + site[5] * (z - site[2]));
        }
      }
    }
  });
  // Tissue within the maximum depth on a face of the box that is not the CT's: grow there.
  vtkIdType underSkin = 0;
  for (vtkIdType id = 0; id < N; ++id)
  {
    if ((p.Class[id] & FilledTissue) && p.Depth[id] <= this->MaximumDepth)
    {
      // The skin's own partial-volume voxels (air against bone looks like
      // soft tissue there) do not make a resection: tissue under them does.
      underSkin += p.Depth[id] > impl.MaxSpacing() ? 1 : 0;
      const int at[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
      for (int a = 0; a < 3; ++a)
      {
        p.Reached[2 * a] |= at[a] == 0 && p.Box[2 * a] > 0;
        p.Reached[2 * a + 1] |= at[a] == p.Size[a] - 1 && p.Box[2 * a + 1] < impl.Dims[a] - 1;
      }
    }
  }
  if (underSkin == 0)
  {
    std::ostringstream text;
    text << "BuildMask: the outline encloses no soft tissue (CT values " << this->SoftTissueRange[0] << " to " << this->SoftTissueRange[1]
         << " HU) more than a voxel under the skin; nothing to resect there";
    impl.Spare = std::move(impl.Next);
    return this->Fail(text.str());
  }
  p.MaskReady = true;
  impl.Spare = std::move(impl.Current);
  impl.Current = std::move(impl.Next);
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::HasPlan() const
{
  return this->Impl->Current != nullptr;
}

//------------------------------------------------------------------------------
namespace
{
/**
 * Signed distance (mm, negative inside) of a box voxel to the shape's wall,
 * where the inner and outer strips are equally near: to first order,
 * (D_in - D_out) / |grad D_in - grad D_out|, with D the exact distances to
 * the strips' segments. The strips are offsets of the same outline points,
 * so the nearest segments of both lie around the index of the nearest site.
 */
float WallDistance(const PlanData& p, const double spacing[3], double maxSpacing, vtkIdType id)
{
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];
  const Vec x = { (p.Box[0] + static_cast<int>(id % sx)) * spacing[0], (p.Box[2] + static_cast<int>((id / sx) % p.Size[1])) * spacing[1],
    (p.Box[4] + static_cast<int>(id / sxy)) * spacing[2] };
  const auto found = p.StripSites.find(p.Feature[id]);
  const int n = static_cast<int>(p.Points.size());
  const int center = found != p.StripSites.end() ? found->second : 0;
  auto evaluate = [&](int window) {
    double bestIn = std::numeric_limits<double>::infinity();
    double bestOut = std::numeric_limits<double>::infinity();
    Vec footIn{ 0.0, 0.0, 0.0 };
    Vec footOut{ 0.0, 0.0, 0.0 };
    for (int offset = -window; offset <= window; ++offset)
    {
      const int k = ((center + offset) % n + n) % n;
      Vec candidate;
      double d2 = SegmentDistance2(x, p.Inner[k], p.Inner[(k + 1) % n], candidate);
      if (d2 < bestIn)
      {
        bestIn = d2;
        footIn = candidate;
      }
      d2 = SegmentDistance2(x, p.Outer[k], p.Outer[(k + 1) % n], candidate);
      if (d2 < bestOut)
      {
        bestOut = d2;
        footOut = candidate;
      }
    }
    const double dIn = std::sqrt(bestIn);
    const double dOut = std::sqrt(bestOut);
    const Vec gradient = Sub(dIn > 0.0 ? Scale(Sub(x, footIn), 1.0 / dIn) : Vec{ 0.0, 0.0, 0.0 },
      dOut > 0.0 ? Scale(Sub(x, footOut), 1.0 / dOut) : Vec{ 0.0, 0.0, 0.0 });
    return (dIn - dOut) / std::max(0.05, Norm(gradient));
  };
  // Far from the wall a rough value is enough: it only has to say which side.
  const double rough = evaluate(1);
  if (std::abs(rough) > 6.0 * maxSpacing)
  {
    return static_cast<float>(rough);
  }
  // Segments within three voxels of arc on either side.
  const double arcStep = std::max(1e-6, p.Length / n);
  const int window = std::min(n / 2, 1 + static_cast<int>(std::ceil(3.0 * maxSpacing / arcStep)));
  return static_cast<float>(evaluate(window));
}

/**
 * The bone's side (positive inside bone) of the CT's iso-surface at the top
 * of the soft-tissue range, as a distance-like value (mm): (CT - threshold)
 * / slope, clamped to a few voxels, with one slope for the whole box (the
 * jump from soft tissue to the threshold over two voxels), so that its
 * trilinear zero set is exactly the CT's trilinear iso-surface. The
 * resection stops at that smooth surface, so the print it leaves on bone is
 * the bone's shape, not voxel steps.
 */
float BoneDistance(const PlanData& p, double slope, double maxSpacing, float threshold, vtkIdType id)
{
  const double reach = 4.0 * maxSpacing;
  return static_cast<float>(std::max(-reach, std::min(reach, (p.Values[id] - threshold) / slope)));
}

/**
 * Whether a box voxel is bone through and through: its value and its 26
 * neighbours' are above the soft-tissue range. Its cube is kept exactly;
 * the voxels of the bone's surface, mixtures of bone and soft tissue, are
 * kept by the smooth surface of BoneDistance up to their centres.
 */
bool IsInsideBone(const PlanData& p, vtkIdType id, float threshold)
{
  if (!(p.Values[id] > threshold))
  {
    return false;
  }
  const int at[3] = { static_cast<int>(id % p.Size[0]), static_cast<int>((id / p.Size[0]) % p.Size[1]),
    static_cast<int>(id / (static_cast<vtkIdType>(p.Size[0]) * p.Size[1])) };
  for (int a = 0; a < 3; ++a)
  {
    if (at[a] == 0 || at[a] + 1 == p.Size[a])
    {
      return false;
    }
  }
  for (int dc = -1; dc <= 1; ++dc)
  {
    for (int db = -1; db <= 1; ++db)
    {
      for (int da = -1; da <= 1; ++da)
      {
        if (!(p.Values[p.Index(at[0] + da, at[1] + db, at[2] + dc)] > threshold))
        {
          return false;
        }
      }
    }
  }
  return true;
}
} // namespace


//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildRegion(double depth, vtkImageData* distances, vtkImageData* keep, vtkVolumeCutField* shieldSource)
{
  this->ErrorMessage.clear();
  Internals& impl = *this->Impl;
  if (!impl.Current)
  {
    return this->Fail("BuildRegion: there is no plan; call Plan with an outline first");
  }
  if (!distances || !keep)
  {
    return this->Fail("BuildRegion: give images for the distances and the voxels kept");
  }
  if (!(depth > 0.0) || !std::isfinite(depth))
  {
    std::ostringstream text;
    text << "BuildRegion: the depth of cut must be a positive number of mm (got " << depth << "); nothing to carve";
    return this->Fail(text.str());
  }
  if (depth > this->MaximumDepth + 1e-9)
  {
    std::ostringstream text;
    text << "BuildRegion: the depth of cut " << depth << " mm is beyond the planned maximum depth of " << this->MaximumDepth
         << " mm; plan again with a larger maximum depth";
    return this->Fail(text.str());
  }
  PlanData& p = *impl.Current;
  const double* spacing = impl.Spacing;
  const double margin = 2.0 * impl.MaxSpacing();
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];

  // Voxels next to filled tissue (26-neighbours): removable, so that the
  // smooth wall and depth, not voxel cubes, bound the region. The wall's and
  // the bone's distances are computed where a region first needs them.
  if (!p.NearFilledReady)
  {
    p.Wall.assign(p.Count, std::numeric_limits<float>::quiet_NaN());
    p.Bone.assign(p.Count, std::numeric_limits<float>::quiet_NaN());
    std::vector<uint8_t> near(p.Count);
    for (vtkIdType id = 0; id < p.Count; ++id)
    {
      near[id] = (p.Class[id] & FilledTissue) ? 1 : 0;
    }
    const vtkIdType steps[3] = { 1, sx, sxy };
    for (int a = 0; a < 3; ++a)
    {
      std::vector<uint8_t> grown(near);
      for (vtkIdType id = 0; id < p.Count; ++id)
      {
        const int at = a == 0 ? static_cast<int>(id % sx) : a == 1 ? static_cast<int>((id / sx) % p.Size[1]) : static_cast<int>(id / sxy);
        if ((at > 0 && near[id - steps[a]]) || (at + 1 < p.Size[a] && near[id + steps[a]]))
        {
          grown[id] = 1;
        }
      }
      near.swap(grown);
    }
    for (vtkIdType id = 0; id < p.Count; ++id)
    {
      p.Class[id] |= near[id] ? NearFilled : 0;
    }
    p.NearFilledReady = true;
  }

  // The part of the box the region reaches: filled tissue above the depth
  // of cut, and a few voxels around it.
  int lower[3] = { p.Size[0], p.Size[1], p.Size[2] };
  int upper[3] = { -1, -1, -1 };
  for (vtkIdType id = 0; id < p.Count; ++id)
  {
    if ((p.Class[id] & FilledTissue) && p.Depth[id] <= depth)
    {
      const int at[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
      for (int a = 0; a < 3; ++a)
      {
        lower[a] = std::min(lower[a], at[a]);
        upper[a] = std::max(upper[a], at[a]);
      }
    }
  }
  if (upper[0] < 0)
  {
    std::ostringstream text;
    text << "BuildRegion: no soft tissue inside the outline lies within " << depth << " mm of the skin; nothing to carve";
    return this->Fail(text.str());
  }
  int sub[6];
  for (int a = 0; a < 3; ++a)
  {
    const int pad = 3 + static_cast<int>(std::ceil(margin / spacing[a]));
    sub[2 * a] = std::max(0, lower[a] - pad);
    sub[2 * a + 1] = std::min(p.Size[a] - 1, upper[a] + pad);
  }
  const int size[3] = { sub[1] - sub[0] + 1, sub[3] - sub[2] + 1, sub[5] - sub[4] + 1 };
  const int extent[6] = { p.Box[0] + sub[0], p.Box[0] + sub[1], p.Box[2] + sub[2], p.Box[2] + sub[3], p.Box[4] + sub[4], p.Box[4] + sub[5] };
  const vtkIdType count = static_cast<vtkIdType>(size[0]) * size[1] * size[2];

  distances->Initialize();
  distances->SetExtent(const_cast<int*>(extent));
  distances->SetOrigin(0.0, 0.0, 0.0);
  distances->SetSpacing(1.0, 1.0, 1.0);
  vtkNew<vtkFloatArray> values;
  values->SetName("ResectionDistance");
  values->SetNumberOfComponents(RegionComponents);
  values->SetNumberOfTuples(count);
  distances->GetPointData()->SetScalars(values);
  keep->Initialize();
  keep->SetExtent(const_cast<int*>(extent));
  keep->SetOrigin(0.0, 0.0, 0.0);
  keep->SetSpacing(1.0, 1.0, 1.0);
  vtkNew<vtkUnsignedCharArray> kept;
  kept->SetName("Keep");
  kept->SetNumberOfTuples(count);
  keep->GetPointData()->SetScalars(kept);
  std::vector<uint8_t> shield;
  if (shieldSource && shieldSource->GetProtection())
  {
    shield.resize(count);
    const int voxelLower[3] = { extent[0], extent[2], extent[4] };
    const int voxelUpper[3] = { extent[1], extent[3], extent[5] };
    shieldSource->GetProtection()->GetShieldLabels(voxelLower, voxelUpper, shield.data());
  }
  float* out = values->GetPointer(0);
  unsigned char* keepOut = kept->GetPointer(0);
  const float low = static_cast<float>(this->SoftTissueRange[0]);
  const float high = static_cast<float>(this->SoftTissueRange[1]);
  const double maxSpacing = impl.MaxSpacing();
  // A voxel's cube meets the region only where the region's value at its
  // centre is below the cube's half diagonal.
  const float nearKept = static_cast<float>(maxSpacing);
  const double boneSlope = std::max(1.0, this->SoftTissueRange[1] - this->SoftTissueRange[0]) / (2.0 * maxSpacing);
  vtkVolumeCutSoftCutThreads::For(0, size[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType c = begin; c < end; ++c)
    {
      for (int b = 0; b < size[1]; ++b)
      {
        vtkIdType target = (c * size[1] + b) * static_cast<vtkIdType>(size[0]);
        vtkIdType id = p.Index(sub[0], sub[2] + b, sub[4] + static_cast<int>(c));
        for (int a = 0; a < size[0]; ++a, ++id, ++target)
        {
          float& wall = p.Wall[id];
          if (std::isnan(wall))
          {
            wall = WallDistance(p, spacing, maxSpacing, id);
          }
          float& bone = p.Bone[id];
          if (std::isnan(bone))
          {
            bone = BoneDistance(p, boneSlope, maxSpacing, high, id);
          }
          const float d = p.Depth[id];
          float* components = out + RegionComponents * target;
          components[0] = wall;
          components[1] = static_cast<float>(d - depth);
          components[2] = static_cast<float>(-(d + margin));
          components[3] = bone;
          // Voxels kept as cubes, where the region comes near them (farther
          // ones change nothing, and each costs the writer a shield brick):
          // bone through and through, and tissue the fill did not reach
          // (behind bone or air) that the region could reach.
          const bool near = std::max({ components[0], components[1], components[2], components[3] }) < nearKept;
          const float value = p.Values[id];
          const bool unreached = value >= low && !(p.Class[id] & NearFilled);
          keepOut[target] = ((near && (unreached || IsInsideBone(p, id, high))) || (!shield.empty() && shield[target])) ? 1 : 0;
        }
      }
    }
  });
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Carve(vtkVolumeCutField* field, double depth, vtkVolumeCutField* shieldSource)
{
  if (!field || field->GetSubVoxelFactor() < 1)
  {
    return this->Fail("Carve: the cut field is not initialized; initialize it on the CT's grid first");
  }
  const int* fieldDims = field->GetDimensions();
  const int f = field->GetSubVoxelFactor();
  if (this->Impl->Current && (fieldDims[0] != this->Impl->Dims[0] * f || fieldDims[1] != this->Impl->Dims[1] * f || fieldDims[2] != this->Impl->Dims[2] * f))
  {
    return this->Fail("Carve: the cut field is not on the planned CT's grid; nothing was carved");
  }
  vtkNew<vtkImageData> distances;
  vtkNew<vtkImageData> keep;
  if (!this->BuildRegion(depth, distances, keep, shieldSource))
  {
    return false;
  }
  if (!field->CutSampledRegion(distances, keep))
  {
    return this->Fail("Carve: the cut field refused the region (see the log); nothing was carved");
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildResectedTissueFunction(double depth, int subdivision, vtkImageData* function)
{
  if (!function || (subdivision != 1 && subdivision != 2))
  {
    return this->Fail("BuildResectedTissueFunction: give an image and a subdivision of 1 or 2");
  }
  vtkNew<vtkImageData> distances;
  vtkNew<vtkImageData> keep;
  if (!this->BuildRegion(depth, distances, keep))
  {
    return false;
  }
  const int* extent = distances->GetExtent();
  const int size[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1 };
  const double margin = 2.0 * this->Impl->MaxSpacing();
  const double unit = this->Impl->MinSpacing();
  // The kept voxels' cubes as a distance (voxel units, scaled by the
  // smallest spacing): exact half-way between a kept voxel and its neighbour.
  std::vector<float> kept(static_cast<size_t>(size[0]) * size[1] * size[2]);
  {
    std::vector<unsigned char> sites(kept.size());
    const unsigned char* keepValues = static_cast<unsigned char*>(keep->GetScalarPointer());
    std::copy(keepValues, keepValues + kept.size(), sites.begin());
    const double unitSpacing[3] = { 1.0, 1.0, 1.0 };
    vtkVolumeCutDistanceTransform::Compute(size, unitSpacing, sites.data(), kept.data(), nullptr);
    for (size_t id = 0; id < kept.size(); ++id)
    {
      kept[id] = sites[id] ? static_cast<float>(0.5 * unit) : static_cast<float>(unit * (0.5 - std::sqrt(kept[id])));
    }
  }
  const float* region = static_cast<float*>(distances->GetScalarPointer());
  // The region's components with the skin itself (-depth) for the air
  // margin's, and the kept cubes.
  auto component = [&](int a, int b, int c, int which) -> float {
    const size_t id = (static_cast<size_t>(c) * size[1] + b) * size[0] + a;
    if (which == RegionComponents)
    {
      return kept[id];
    }
    const float value = region[RegionComponents * id + which];
    return which == 2 ? static_cast<float>(value + margin) : value;
  };
  // One sample of padding, positive, closes the surface at the image's faces.
  const int s = subdivision;
  const int samples[3] = { (size[0] - 1) * s + 3, (size[1] - 1) * s + 3, (size[2] - 1) * s + 3 };
  function->Initialize();
  function->SetDimensions(const_cast<int*>(samples));
  function->SetSpacing(1.0 / s, 1.0 / s, 1.0 / s);
  function->SetOrigin(extent[0] - 1.0 / s, extent[2] - 1.0 / s, extent[4] - 1.0 / s);
  vtkNew<vtkFloatArray> values;
  values->SetName("ResectedTissue");
  values->SetNumberOfTuples(static_cast<vtkIdType>(samples[0]) * samples[1] * samples[2]);
  function->GetPointData()->SetScalars(values);
  float* out = values->GetPointer(0);
  vtkVolumeCutSoftCutThreads::For(0, samples[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType qz = begin; qz < end; ++qz)
    {
      for (int qy = 0; qy < samples[1]; ++qy)
      {
        for (int qx = 0; qx < samples[0]; ++qx)
        {
          const int q[3] = { qx, qy, static_cast<int>(qz) };
          float& target = out[(static_cast<size_t>(qz) * samples[1] + qy) * samples[0] + qx];
          if (q[0] == 0 || q[1] == 0 || q[2] == 0 || q[0] == samples[0] - 1 || q[1] == samples[1] - 1 || q[2] == samples[2] - 1)
          {
            target = static_cast<float>(unit);
            continue;
          }
          int base[3];
          double f[3];
          for (int a = 0; a < 3; ++a)
          {
            const int local = q[a] - 1;
            base[a] = std::min(local / s, size[a] - 2 >= 0 ? size[a] - 2 : 0);
            f[a] = size[a] > 1 ? double(local) / s - base[a] : 0.0;
          }
          float result = -std::numeric_limits<float>::infinity();
          for (int which = 0; which <= RegionComponents; ++which)
          {
            double value = 0.0;
            for (int corner = 0; corner < 8; ++corner)
            {
              const int d[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
              const double w = (d[0] ? f[0] : 1.0 - f[0]) * (d[1] ? f[1] : 1.0 - f[1]) * (d[2] ? f[2] : 1.0 - f[2]);
              if (w != 0.0)
              {
                value += w * component(std::min(size[0] - 1, base[0] + d[0]), std::min(size[1] - 1, base[1] + d[1]), std::min(size[2] - 1, base[2] + d[2]), which);
              }
            }
            result = std::max(result, static_cast<float>(value));
          }
          target = result;
        }
      }
    }
  });
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetBoxExtent(int extent[6]) const
{
  const PlanData* p = this->Impl->Current.get();
  for (int i = 0; i < 6; ++i)
  {
    extent[i] = p ? p->Box[i] : (i % 2 ? -1 : 0);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetOutlineOnSkin(vtkPolyData* polyline) const
{
  this->Impl->CopyPolyline(&PlanData::Points, polyline);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetInnerStrip(vtkPolyData* polyline) const
{
  this->Impl->CopyPolyline(&PlanData::Inner, polyline);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetOuterStrip(vtkPolyData* polyline) const
{
  this->Impl->CopyPolyline(&PlanData::Outer, polyline);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetAverageNormal(double normal[3]) const
{
  const Vec n = this->Impl->Current ? this->Impl->VectorToRAS(this->Impl->Current->AverageNormal) : Vec{ 0.0, 0.0, 0.0 };
  std::copy(n.begin(), n.end(), normal);
}

//------------------------------------------------------------------------------
double vtkVolumeCutResectionPlanner::GetOutlineLength() const
{
  return this->Impl->Current ? this->Impl->Current->Length : 0.0;
}

//------------------------------------------------------------------------------
double vtkVolumeCutResectionPlanner::GetProjectedArea() const
{
  return this->Impl->Current ? this->Impl->Current->Area : 0.0;
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutResectionPlanner::GetNumberOfFilledVoxels() const
{
  return this->Impl->Current ? this->Impl->Current->FilledCount : 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetShapeImage(vtkImageData* image) const
{
  const PlanData* p = this->Impl->StartBoxImage(image);
  if (!p)
  {
    return;
  }
  vtkNew<vtkUnsignedCharArray> classes;
  classes->SetName("Shape");
  classes->SetNumberOfTuples(p->Count);
  for (vtkIdType id = 0; id < p->Count; ++id)
  {
    classes->SetValue(id, p->Class[id] & (InShape | SkinPatch | FilledTissue));
  }
  image->GetPointData()->SetScalars(classes);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetDepthImage(vtkImageData* image) const
{
  const PlanData* p = this->Impl->StartBoxImage(image);
  if (!p)
  {
    return;
  }
  vtkNew<vtkFloatArray> depth;
  depth->SetName("Depth");
  depth->SetNumberOfTuples(p->Count);
  std::copy(p->Depth.begin(), p->Depth.end(), depth->GetPointer(0));
  image->GetPointData()->SetScalars(depth);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NormalMode: " << (this->NormalMode == LocalNormal ? "LocalNormal" : "AverageNormal") << "\n";
  os << indent << "SkinIsoValue: " << this->SkinIsoValue << "\n";
  os << indent << "SoftTissueRange: " << this->SoftTissueRange[0] << " " << this->SoftTissueRange[1] << "\n";
  os << indent << "StripOffset: " << this->StripOffset << "\n";
  os << indent << "MaximumDepth: " << this->MaximumDepth << "\n";
  os << indent << "SkinTolerance: " << this->SkinTolerance << "\n";
  os << indent << "Planned: " << (this->HasPlan() ? "yes" : "no") << "\n";
}
