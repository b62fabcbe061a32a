// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutNerveMonitor.h"
#include "vtkVolumeCutNerveMonitorField.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkVolumeCutThreadClock.h"
#include "vtkVolumeCutTool.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>

vtkStandardNewMacro(vtkVolumeCutNerveMonitor);

namespace
{
/// Points on a tool's surface (tool frame, mm, x y z interleaved): a fine set
/// for structures near the tool, a coarse one for those farther than the
/// silent threshold.
struct ToolSamples
{
  vtkVolumeCutTool* Tool = nullptr; // identity only, never dereferenced by measurements
  vtkMTimeType ToolTime = 0;
  double BoundingRadius = 0.0;
  std::vector<double> Fine;
  std::vector<double> Coarse;
};

/// Place points step apart on the zero set of the tool's distance: grid
/// points near it, each moved onto it by Newton's iteration.
void SampleToolSurface(vtkVolumeCutTool* tool, double step, std::vector<double>& points)
{
  double half[3];
  tool->GetLocalHalfExtents(half);
  int count[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    count[axis] = static_cast<int>(std::ceil(2.0 * half[axis] / step)) + 1;
  }
  const double epsilon = 1e-4 * step;
  for (int k = 0; k < count[2]; ++k)
  {
    for (int j = 0; j < count[1]; ++j)
    {
      for (int i = 0; i < count[0]; ++i)
      {
        double x[3] = { -half[0] + i * step, -half[1] + j * step, -half[2] + k * step };
        double value = tool->EvaluateDistance(x);
        if (!(std::abs(value) < 0.75 * step))
        {
          continue;
        }
        for (int iteration = 0; iteration < 8 && std::abs(value) > 1e-6; ++iteration)
        {
          double gradient[3];
          double norm2 = 0.0;
          for (int axis = 0; axis < 3; ++axis)
          {
            double plus[3] = { x[0], x[1], x[2] };
            double minus[3] = { x[0], x[1], x[2] };
            plus[axis] += epsilon;
            minus[axis] -= epsilon;
            gradient[axis] = (tool->EvaluateDistance(plus) - tool->EvaluateDistance(minus)) / (2.0 * epsilon);
            norm2 += gradient[axis] * gradient[axis];
          }
          if (norm2 < 1e-12)
          {
            break;
          }
          for (int axis = 0; axis < 3; ++axis)
          {
            x[axis] -= value * gradient[axis] / norm2;
          }
          value = tool->EvaluateDistance(x);
        }
        if (std::abs(value) < 1e-3 * step)
        {
          points.insert(points.end(), x, x + 3);
        }
      }
    }
  }
}

/// Scan one image's voxels of a value inside a box of anatomy voxels.
struct LabelReader
{
  vtkImageData* Image;
  int Value;
  int Extent[6];

  /// Anatomy voxel bounds of the value within the scan (empty box if none).
  template <typename T>
  void FindBox(const T*, const int dims[3], int box[6]) const
  {
    box[0] = box[2] = box[4] = std::numeric_limits<int>::max();
    box[1] = box[3] = box[5] = -1;
    const int lower[3] = { std::max(this->Extent[0], 0), std::max(this->Extent[2], 0), std::max(this->Extent[4], 0) };
    const int upper[3] = { std::min(this->Extent[1], dims[0] - 1), std::min(this->Extent[3], dims[1] - 1), std::min(this->Extent[5], dims[2] - 1) };
    for (int k = lower[2]; k <= upper[2]; ++k)
    {
      for (int j = lower[1]; j <= upper[1]; ++j)
      {
        const T* row = static_cast<const T*>(this->Image->GetScalarPointer(lower[0], j, k));
        for (int i = lower[0]; i <= upper[0]; ++i)
        {
          if (row[i - lower[0]] == static_cast<T>(this->Value))
          {
            box[0] = std::min(box[0], i);
            box[1] = std::max(box[1], i);
            box[2] = std::min(box[2], j);
            box[3] = std::max(box[3], j);
            box[4] = std::min(box[4], k);
            box[5] = std::max(box[5], k);
          }
        }
      }
    }
  }

  /// The mask (1: the value) of the anatomy voxels origin .. origin + dims - 1.
  template <typename T>
  void ReadMask(const T*, const int origin[3], const int dims[3], std::vector<uint16_t>& mask) const
  {
    mask.assign(static_cast<size_t>(dims[0]) * dims[1] * dims[2], 0);
    for (int k = 0; k < dims[2]; ++k)
    {
      const int ak = origin[2] + k;
      for (int j = 0; j < dims[1]; ++j)
      {
        const int aj = origin[1] + j;
        if (ak < this->Extent[4] || ak > this->Extent[5] || aj < this->Extent[2] || aj > this->Extent[3])
        {
          continue;
        }
        const int first = std::max(origin[0], this->Extent[0]);
        const int last = std::min(origin[0] + dims[0] - 1, this->Extent[1]);
        if (first > last)
        {
          continue;
        }
        const T* row = static_cast<const T*>(this->Image->GetScalarPointer(first, aj, ak));
        uint16_t* out = mask.data() + (first - origin[0]) + static_cast<size_t>(dims[0]) * (j + static_cast<size_t>(dims[1]) * k);
        for (int i = first; i <= last; ++i)
        {
          out[i - first] = row[i - first] == static_cast<T>(this->Value) ? 1 : 0;
        }
      }
    }
  }
};
}

/// What measurements read: immutable once published.
struct vtkVolumeCutNerveMonitorSnapshot
{
  std::vector<std::shared_ptr<const vtkVolumeCutNerveMonitorField>> Fields; // nullptr: not built yet
  double RASToIJK[16];
  double Silent = 4.0;
  double Sparse = 2.0;
  double Bursts = 1.0;
  double MaximumRate = 200.0;
  std::shared_ptr<const ToolSamples> Tool;

  int Level(double distance) const
  {
    if (std::isnan(distance))
    {
      return vtkVolumeCutNerveMonitor::NotReady;
    }
    return distance <= 0.0 ? vtkVolumeCutNerveMonitor::Contact
      : distance <= this->Bursts ? vtkVolumeCutNerveMonitor::Continuous
      : distance <= this->Sparse ? vtkVolumeCutNerveMonitor::Bursts
      : distance <= this->Silent ? vtkVolumeCutNerveMonitor::SparseClicks
                                 : vtkVolumeCutNerveMonitor::Silent;
  }
  double Rate(double distance) const
  {
    if (!(distance < this->Silent))
    {
      return 0.0;
    }
    const double closeness = distance <= 0.0 ? 1.0 : 1.0 - distance / this->Silent;
    return this->MaximumRate * closeness * closeness;
  }
  void ToIJK(const double ras[3], double ijk[3]) const
  {
    for (int row = 0; row < 3; ++row)
    {
      const double* m = this->RASToIJK + 4 * row;
      ijk[row] = m[0] * ras[0] + m[1] * ras[1] + m[2] * ras[2] + m[3];
    }
  }
};

struct vtkVolumeCutNerveMonitor::Internals
{
  struct Structure
  {
    std::string Name;
    vtkSmartPointer<vtkImageData> Labels;
    int Value = 0;
    int Box[6] = { 0, -1, 0, -1, 0, -1 };
  };

  // The owner's configuration (Structures changes under ConfigurationMutex, which Build reads under).
  bool HasGeometry = false;
  int Dimensions[3] = { 0, 0, 0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double RASToIJK[16];
  std::vector<Structure> Structures;
  std::vector<std::shared_ptr<const vtkVolumeCutNerveMonitorField>> Fields;
  unsigned long long Generation = 0; // a Build of an older generation drops its fields
  double Silent = 4.0, Sparse = 2.0, Bursts = 1.0, MaximumRate = 200.0;
  std::shared_ptr<const ToolSamples> Tool;
  std::mutex ConfigurationMutex;
  std::mutex BuildMutex;

  // Publication: readers count themselves in before loading the snapshot;
  // retired snapshots are freed once no reader is in.
  std::atomic<const vtkVolumeCutNerveMonitorSnapshot*> Current{ nullptr };
  std::atomic<int> Readers{ 0 };
  std::vector<std::unique_ptr<const vtkVolumeCutNerveMonitorSnapshot>> Retired;
  std::mutex PublishMutex;

  /// Publish the configuration as it is now (ConfigurationMutex held).
  void Publish()
  {
    auto snapshot = std::make_unique<vtkVolumeCutNerveMonitorSnapshot>();
    snapshot->Fields = this->Fields;
    std::copy(this->RASToIJK, this->RASToIJK + 16, snapshot->RASToIJK);
    snapshot->Silent = this->Silent;
    snapshot->Sparse = this->Sparse;
    snapshot->Bursts = this->Bursts;
    snapshot->MaximumRate = this->MaximumRate;
    snapshot->Tool = this->Tool;
    std::lock_guard<std::mutex> lock(this->PublishMutex);
    const vtkVolumeCutNerveMonitorSnapshot* old = this->Current.exchange(snapshot.release(), std::memory_order_seq_cst);
    if (old)
    {
      this->Retired.emplace_back(old);
    }
    if (this->Readers.load(std::memory_order_seq_cst) == 0)
    {
      this->Retired.clear();
    }
  }

  /// A measurement's hold on the current snapshot.
  struct ReadGuard
  {
    const Internals& Owner;
    const vtkVolumeCutNerveMonitorSnapshot* Snapshot;
    explicit ReadGuard(const Internals& owner)
      : Owner(owner)
    {
      const_cast<std::atomic<int>&>(owner.Readers).fetch_add(1, std::memory_order_seq_cst);
      this->Snapshot = owner.Current.load(std::memory_order_seq_cst);
    }
    ~ReadGuard() { const_cast<std::atomic<int>&>(this->Owner.Readers).fetch_sub(1, std::memory_order_release); }
  };

  ~Internals()
  {
    delete this->Current.load();
  }
};

//------------------------------------------------------------------------------
vtkVolumeCutNerveMonitor::vtkVolumeCutNerveMonitor()
  : Internal(new Internals)
{
  vtkMatrix4x4::Identity(this->Internal->RASToIJK);
  std::lock_guard<std::mutex> lock(this->Internal->ConfigurationMutex);
  this->Internal->Publish();
}

//------------------------------------------------------------------------------
vtkVolumeCutNerveMonitor::~vtkVolumeCutNerveMonitor()
{
  // A Build on a worker must have returned before the monitor goes.
  std::lock_guard<std::mutex> lock(this->Internal->BuildMutex);
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutNerveMonitor::GetLevelAsString(int level)
{
  switch (level)
  {
    case Silent:
      return "silent";
    case SparseClicks:
      return "sparse clicks";
    case Bursts:
      return "bursts";
    case Continuous:
      return "continuous";
    case Contact:
      return "contact";
    default:
      return "not ready";
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutNerveMonitor::SetGeometry(const int dimensions[3], vtkMatrix4x4* ijkToRAS)
{
  if (!ijkToRAS)
  {
    vtkErrorMacro("SetGeometry: no IJK-to-RAS matrix");
    return false;
  }
  if (dimensions[0] < 1 || dimensions[1] < 1 || dimensions[2] < 1)
  {
    vtkErrorMacro("SetGeometry: the scan must have at least one voxel along each axis");
    return false;
  }
  double columns[3][3];
  double spacing[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int row = 0; row < 3; ++row)
    {
      columns[axis][row] = ijkToRAS->GetElement(row, axis);
    }
    spacing[axis] = std::sqrt(columns[axis][0] * columns[axis][0] + columns[axis][1] * columns[axis][1] + columns[axis][2] * columns[axis][2]);
    if (!(spacing[axis] > 0.0) || !std::isfinite(spacing[axis]))
    {
      vtkErrorMacro("SetGeometry: the spacing along axis " << axis << " is " << spacing[axis] << " mm; it must be positive and finite");
      return false;
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    for (int b = a + 1; b < 3; ++b)
    {
      const double dot = columns[a][0] * columns[b][0] + columns[a][1] * columns[b][1] + columns[a][2] * columns[b][2];
      if (std::abs(dot) > 1e-4 * spacing[a] * spacing[b])
      {
        vtkErrorMacro("SetGeometry: the scan's IJK axes " << a << " and " << b << " are not at right angles (a sheared or gantry-tilted grid, angle "
                                                         << std::acos(dot / (spacing[a] * spacing[b])) * 180.0 / 3.141592653589793
                                                         << " degrees); resample it onto an orthogonal grid to monitor its structures");
        return false;
      }
    }
  }
  vtkNew<vtkMatrix4x4> rasToIJK;
  vtkMatrix4x4::Invert(ijkToRAS, rasToIJK);
  {
    std::lock_guard<std::mutex> lock(this->Internal->ConfigurationMutex);
    Internals& internal = *this->Internal;
    internal.HasGeometry = true;
    std::copy(dimensions, dimensions + 3, internal.Dimensions);
    std::copy(spacing, spacing + 3, internal.Spacing);
    std::copy(&rasToIJK->GetData()[0], &rasToIJK->GetData()[0] + 16, internal.RASToIJK);
    internal.Structures.clear();
    internal.Fields.clear();
    ++internal.Generation;
    internal.Publish();
  }
  this->Readings.clear();
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::AddStructure(const char* name, vtkImageData* labels, int value)
{
  Internals& internal = *this->Internal;
  const std::string structureName = name ? name : "";
  if (!internal.HasGeometry)
  {
    vtkErrorMacro("AddStructure: structure '" << structureName << "': set the scan's geometry first (SetGeometry)");
    return -1;
  }
  if (structureName.empty())
  {
    vtkErrorMacro("AddStructure: a monitored structure needs a name");
    return -1;
  }
  if (this->GetStructureIndex(structureName.c_str()) >= 0)
  {
    vtkErrorMacro("AddStructure: structure '" << structureName << "' is monitored already");
    return -1;
  }
  vtkDataArray* scalars = labels ? labels->GetPointData()->GetScalars() : nullptr;
  if (!scalars || scalars->GetNumberOfComponents() != 1 || !scalars->IsIntegral())
  {
    vtkErrorMacro("AddStructure: structure '" << structureName << "' needs a label image with one integer component");
    return -1;
  }
  Internals::Structure structure;
  structure.Name = structureName;
  structure.Labels = labels;
  structure.Value = value;
  LabelReader reader{ labels, value, {} };
  labels->GetExtent(reader.Extent);
  switch (scalars->GetDataType())
  {
    vtkTemplateMacro(reader.FindBox(static_cast<const VTK_TT*>(nullptr), internal.Dimensions, structure.Box));
  }
  if (structure.Box[1] < structure.Box[0])
  {
    vtkErrorMacro("AddStructure: structure '" << structureName << "' has no voxel of value " << value
                                               << " inside the scan (it is empty or outside it); it is not monitored");
    return -1;
  }
  int index;
  {
    std::lock_guard<std::mutex> lock(internal.ConfigurationMutex);
    internal.Structures.push_back(structure);
    internal.Fields.emplace_back();
    index = static_cast<int>(internal.Structures.size()) - 1;
    internal.Publish();
  }
  this->Readings.resize(internal.Structures.size());
  this->Modified();
  return index;
}

//------------------------------------------------------------------------------
void vtkVolumeCutNerveMonitor::RemoveAllStructures()
{
  {
    std::lock_guard<std::mutex> lock(this->Internal->ConfigurationMutex);
    this->Internal->Structures.clear();
    this->Internal->Fields.clear();
    ++this->Internal->Generation;
    this->Internal->Publish();
  }
  this->Readings.clear();
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::GetNumberOfStructures() const
{
  return static_cast<int>(this->Internal->Structures.size());
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutNerveMonitor::GetStructureName(int index) const
{
  if (index < 0 || index >= this->GetNumberOfStructures())
  {
    return nullptr;
  }
  return this->Internal->Structures[index].Name.c_str();
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::GetStructureIndex(const char* name) const
{
  for (size_t index = 0; name && index < this->Internal->Structures.size(); ++index)
  {
    if (this->Internal->Structures[index].Name == name)
    {
      return static_cast<int>(index);
    }
  }
  return -1;
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::Build()
{
  Internals& internal = *this->Internal;
  std::lock_guard<std::mutex> buildLock(internal.BuildMutex);
  std::vector<std::pair<size_t, Internals::Structure>> pending;
  unsigned long long generation;
  int dims[3];
  double spacing[3];
  const double range = this->Range;
  const double contactRange = std::min(this->ContactRange, this->Range);
  const double smoothing = this->Smoothing;
  {
    std::lock_guard<std::mutex> lock(internal.ConfigurationMutex);
    generation = internal.Generation;
    std::copy(internal.Dimensions, internal.Dimensions + 3, dims);
    std::copy(internal.Spacing, internal.Spacing + 3, spacing);
    for (size_t index = 0; index < internal.Structures.size(); ++index)
    {
      if (!internal.Fields[index])
      {
        pending.emplace_back(index, internal.Structures[index]);
      }
    }
  }
  const auto start = std::chrono::steady_clock::now();
  double longest = 0.0;
  int built = 0;
  for (const auto& entry : pending)
  {
    const auto structureStart = std::chrono::steady_clock::now();
    const Internals::Structure& structure = entry.second;
    // The mask reaches Range and the smoothing's reach beyond the structure's voxels.
    int origin[3], maskDims[3], labelBox[6];
    const double reach = range + 4.0 * std::max({ spacing[0], spacing[1], spacing[2] }) + 3.0 * smoothing * std::max({ spacing[0], spacing[1], spacing[2] });
    for (int axis = 0; axis < 3; ++axis)
    {
      const int margin = static_cast<int>(std::ceil(reach / spacing[axis])) + 2;
      origin[axis] = std::max(0, structure.Box[2 * axis] - margin);
      const int last = std::min(dims[axis] - 1, structure.Box[2 * axis + 1] + margin);
      maskDims[axis] = last - origin[axis] + 1;
      labelBox[2 * axis] = structure.Box[2 * axis] - origin[axis];
      labelBox[2 * axis + 1] = structure.Box[2 * axis + 1] - origin[axis];
    }
    std::vector<uint16_t> mask;
    LabelReader reader{ structure.Labels, structure.Value, {} };
    structure.Labels->GetExtent(reader.Extent);
    switch (structure.Labels->GetScalarType())
    {
      vtkTemplateMacro(reader.ReadMask(static_cast<const VTK_TT*>(nullptr), origin, maskDims, mask));
    }
    std::shared_ptr<const vtkVolumeCutNerveMonitorField> field =
      vtkVolumeCutNerveMonitorField::Build(mask.data(), maskDims, origin, spacing, labelBox, smoothing, range, contactRange);
    longest = std::max(longest, std::chrono::duration<double>(std::chrono::steady_clock::now() - structureStart).count());
    std::lock_guard<std::mutex> lock(internal.ConfigurationMutex);
    if (internal.Generation != generation)
    {
      break; // the structures changed meanwhile: this field is no longer wanted
    }
    internal.Fields[entry.first] = field;
    internal.Publish();
    ++built;
  }
  this->LastBuildTime = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  this->LastMaximumStructureBuildTime = longest;
  return built;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutNerveMonitor::IsBuilt() const
{
  Internals::ReadGuard guard(*this->Internal);
  for (const auto& field : guard.Snapshot->Fields)
  {
    if (!field)
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutNerveMonitor::GetMemorySize() const
{
  Internals::ReadGuard guard(*this->Internal);
  size_t size = 0;
  for (const auto& field : guard.Snapshot->Fields)
  {
    size += field ? field->GetMemorySize() : 0;
  }
  return size;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutNerveMonitor::SetThresholds(double silent, double sparse, double bursts)
{
  if (!(silent > sparse && sparse > bursts && bursts > 0.0) || !std::isfinite(silent))
  {
    vtkErrorMacro("SetThresholds: thresholds out of order: silent " << silent << " mm, sparse clicks " << sparse << " mm, bursts " << bursts
                                                                    << " mm; they must decrease and stay above 0 (silent > sparse > bursts > 0)");
    return false;
  }
  std::lock_guard<std::mutex> lock(this->Internal->ConfigurationMutex);
  this->Internal->Silent = silent;
  this->Internal->Sparse = sparse;
  this->Internal->Bursts = bursts;
  this->Internal->Publish();
  this->Modified();
  return true;
}

double vtkVolumeCutNerveMonitor::GetSilentThreshold() const
{
  return this->Internal->Silent;
}
double vtkVolumeCutNerveMonitor::GetSparseThreshold() const
{
  return this->Internal->Sparse;
}
double vtkVolumeCutNerveMonitor::GetBurstThreshold() const
{
  return this->Internal->Bursts;
}

//------------------------------------------------------------------------------
void vtkVolumeCutNerveMonitor::SetMaximumFiringRate(double rate)
{
  rate = std::min(std::max(rate, 0.0), 10000.0);
  if (rate == this->Internal->MaximumRate)
  {
    return;
  }
  std::lock_guard<std::mutex> lock(this->Internal->ConfigurationMutex);
  this->Internal->MaximumRate = rate;
  this->Internal->Publish();
  this->Modified();
}

double vtkVolumeCutNerveMonitor::GetMaximumFiringRate() const
{
  return this->Internal->MaximumRate;
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::GetLevelOfDistance(double distance) const
{
  Internals::ReadGuard guard(*this->Internal);
  return guard.Snapshot->Level(distance);
}

double vtkVolumeCutNerveMonitor::GetFiringRateOfDistance(double distance) const
{
  Internals::ReadGuard guard(*this->Internal);
  return guard.Snapshot->Rate(distance);
}

//------------------------------------------------------------------------------
double vtkVolumeCutNerveMonitor::GetDistanceAt(int index, const double ras[3]) const
{
  double surface, shield;
  return this->GetDistancesAt(index, ras, surface, shield) ? surface : std::numeric_limits<double>::quiet_NaN();
}

double vtkVolumeCutNerveMonitor::GetClearanceAt(int index, const double ras[3]) const
{
  double surface, shield;
  return this->GetDistancesAt(index, ras, surface, shield) ? shield : std::numeric_limits<double>::quiet_NaN();
}

bool vtkVolumeCutNerveMonitor::GetDistancesAt(int index, const double ras[3], double& surface, double& shield) const
{
  Internals::ReadGuard guard(*this->Internal);
  const vtkVolumeCutNerveMonitorSnapshot& snapshot = *guard.Snapshot;
  if (index < 0 || index >= static_cast<int>(snapshot.Fields.size()) || !snapshot.Fields[index])
  {
    return false;
  }
  double ijk[3];
  snapshot.ToIJK(ras, ijk);
  snapshot.Fields[index]->GetDistances(ijk, surface, shield);
  return true;
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::Measure(const double centre[3], double radius, Reading* readings, int capacity) const
{
  Internals::ReadGuard guard(*this->Internal);
  const vtkVolumeCutNerveMonitorSnapshot& snapshot = *guard.Snapshot;
  double ijk[3];
  snapshot.ToIJK(centre, ijk);
  const int count = static_cast<int>(snapshot.Fields.size());
  for (int index = 0; index < count && index < capacity; ++index)
  {
    const vtkVolumeCutNerveMonitorField* field = snapshot.Fields[index].get();
    Reading& reading = readings[index];
    if (field)
    {
      double surface, shield;
      field->GetDistances(ijk, surface, shield);
      reading.Clearance = shield - radius;
      reading.Distance = reading.Clearance > 0.0 ? surface - radius : reading.Clearance;
    }
    else
    {
      reading.Distance = reading.Clearance = std::numeric_limits<double>::quiet_NaN();
    }
    reading.Level = snapshot.Level(reading.Distance);
    reading.FiringRate = snapshot.Rate(reading.Distance);
  }
  return count;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutNerveMonitor::MeasureAlong(
  vtkPoints* centres, double radius, vtkDoubleArray* distances, vtkDoubleArray* microseconds, vtkDoubleArray* processorMicroseconds)
{
  if (!centres || !distances)
  {
    vtkErrorMacro("MeasureAlong: centres and an array for the distances are required");
    return false;
  }
  const int structures = this->GetNumberOfStructures();
  const vtkIdType count = centres->GetNumberOfPoints();
  distances->SetNumberOfComponents(std::max(structures, 1));
  distances->SetNumberOfTuples(count);
  for (vtkDoubleArray* durations : { microseconds, processorMicroseconds })
  {
    if (durations)
    {
      durations->SetNumberOfComponents(1);
      durations->SetNumberOfTuples(count);
    }
  }
  std::vector<Reading> readings(std::max(structures, 1));
  for (vtkIdType n = 0; n < count; ++n)
  {
    double centre[3];
    centres->GetPoint(n, centre);
    const double processorStart = processorMicroseconds ? vtkVolumeCutThreadClock::ProcessorMicroseconds() : 0.0;
    const auto start = std::chrono::steady_clock::now();
    this->Measure(centre, radius, readings.data(), static_cast<int>(readings.size()));
    const auto end = std::chrono::steady_clock::now();
    if (processorMicroseconds)
    {
      processorMicroseconds->SetValue(n, vtkVolumeCutThreadClock::ProcessorMicroseconds() - processorStart);
    }
    for (int index = 0; index < std::max(structures, 1); ++index)
    {
      distances->SetTypedComponent(n, index, index < structures ? readings[index].Distance : std::numeric_limits<double>::quiet_NaN());
    }
    if (microseconds)
    {
      microseconds->SetValue(n, std::chrono::duration<double, std::micro>(end - start).count());
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutNerveMonitor::PrepareTool(vtkVolumeCutTool* tool)
{
  if (!tool || !tool->IsValid())
  {
    vtkErrorMacro("PrepareTool: " << (tool ? "the tool is not valid" : "no tool"));
    return false;
  }
  Internals& internal = *this->Internal;
  if (internal.Tool && internal.Tool->Tool == tool && internal.Tool->ToolTime == tool->GetMTime())
  {
    return true;
  }
  auto samples = std::make_shared<ToolSamples>();
  samples->Tool = tool;
  samples->ToolTime = tool->GetMTime();
  samples->BoundingRadius = tool->GetBoundingRadius();
  double half[3];
  tool->GetLocalHalfExtents(half);
  // At most about 96 steps along the tool's longest side: a 60 mm disk saw
  // is read 0.6 mm apart, a burr SampleSpacing apart.
  const double step = std::max(this->SampleSpacing, 2.0 * std::max({ half[0], half[1], half[2] }) / 96.0);
  SampleToolSurface(tool, step, samples->Fine);
  SampleToolSurface(tool, 4.0 * step, samples->Coarse);
  if (samples->Coarse.empty())
  {
    samples->Coarse = samples->Fine;
  }
  if (samples->Fine.empty())
  {
    vtkErrorMacro("PrepareTool: found no point on the tool's surface");
    return false;
  }
  std::lock_guard<std::mutex> lock(internal.ConfigurationMutex);
  internal.Tool = samples;
  internal.Publish();
  return true;
}

int vtkVolumeCutNerveMonitor::GetNumberOfToolSamples() const
{
  return this->Internal->Tool ? static_cast<int>(this->Internal->Tool->Fine.size() / 3) : 0;
}

//------------------------------------------------------------------------------
int vtkVolumeCutNerveMonitor::MeasureTool(const double toolToRAS[16], Reading* readings, int capacity) const
{
  Internals::ReadGuard guard(*this->Internal);
  const vtkVolumeCutNerveMonitorSnapshot& snapshot = *guard.Snapshot;
  const ToolSamples* tool = snapshot.Tool.get();
  if (!tool)
  {
    return -1;
  }
  // Tool frame to IJK in one matrix.
  double toIJK[12];
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      double sum = column == 3 ? snapshot.RASToIJK[4 * row + 3] : 0.0;
      for (int n = 0; n < 3; ++n)
      {
        sum += snapshot.RASToIJK[4 * row + n] * toolToRAS[4 * n + column];
      }
      toIJK[4 * row + column] = sum;
    }
  }
  const double centre[3] = { toIJK[3], toIJK[7], toIJK[11] };
  const int count = static_cast<int>(snapshot.Fields.size());
  for (int index = 0; index < count && index < capacity; ++index)
  {
    const vtkVolumeCutNerveMonitorField* field = snapshot.Fields[index].get();
    Reading& reading = readings[index];
    if (!field)
    {
      reading.Distance = reading.Clearance = std::numeric_limits<double>::quiet_NaN();
    }
    else
    {
      const bool near = field->GetDistance(centre) - tool->BoundingRadius <= snapshot.Silent;
      const std::vector<double>& points = near ? tool->Fine : tool->Coarse;
      // The shield is nearer than the surface by at most the field's
      // protrusion: a point whose surface distance exceeds the nearest
      // clearance so far by more than that cannot lower it.
      const double protrusion = field->GetMaximumProtrusion();
      double nearest = std::numeric_limits<double>::infinity();
      double clearance = std::numeric_limits<double>::infinity();
      for (size_t n = 0; n < points.size(); n += 3)
      {
        const double* p = points.data() + n;
        const double ijk[3] = { toIJK[0] * p[0] + toIJK[1] * p[1] + toIJK[2] * p[2] + toIJK[3],
          toIJK[4] * p[0] + toIJK[5] * p[1] + toIJK[6] * p[2] + toIJK[7], toIJK[8] * p[0] + toIJK[9] * p[1] + toIJK[10] * p[2] + toIJK[11] };
        const double surface = field->GetDistance(ijk);
        nearest = std::min(nearest, surface);
        if (surface - protrusion < clearance)
        {
          double unused, shield;
          field->GetDistances(ijk, unused, shield);
          clearance = std::min(clearance, shield);
        }
      }
      reading.Clearance = clearance;
      reading.Distance = clearance > 0.0 ? nearest : clearance;
    }
    reading.Level = snapshot.Level(reading.Distance);
    reading.FiringRate = snapshot.Rate(reading.Distance);
  }
  return count;
}

//------------------------------------------------------------------------------
void vtkVolumeCutNerveMonitor::UpdateWithBurr(const double centre[3], double radius)
{
  std::vector<Reading> readings(this->GetNumberOfStructures());
  const int count = this->Measure(centre, radius, readings.data(), static_cast<int>(readings.size()));
  this->UpdateWithReadings(readings.data(), count);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutNerveMonitor::UpdateWithTool(vtkVolumeCutTool* tool, vtkMatrix4x4* toolToRAS)
{
  if (!toolToRAS || !this->PrepareTool(tool))
  {
    if (!toolToRAS)
    {
      vtkErrorMacro("UpdateWithTool: no tool-to-RAS matrix");
    }
    return false;
  }
  std::vector<Reading> readings(this->GetNumberOfStructures());
  const int count = this->MeasureTool(&toolToRAS->GetData()[0], readings.data(), static_cast<int>(readings.size()));
  this->UpdateWithReadings(readings.data(), std::max(count, 0));
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutNerveMonitor::UpdateWithReadings(const Reading* readings, int count)
{
  const size_t structures = this->Internal->Structures.size();
  this->Readings.resize(structures);
  bool levelChanged = false;
  for (size_t index = 0; index < structures && index < static_cast<size_t>(std::max(count, 0)); ++index)
  {
    levelChanged = levelChanged || readings[index].Level != this->Readings[index].Level;
    this->Readings[index] = readings[index];
  }
  if (levelChanged)
  {
    ++this->NumberOfLevelChanges;
    this->InvokeEvent(LevelChangedEvent);
  }
  this->InvokeEvent(ReadingsModifiedEvent);
}

//------------------------------------------------------------------------------
double vtkVolumeCutNerveMonitor::GetDistance(int index) const
{
  return index >= 0 && index < static_cast<int>(this->Readings.size()) ? this->Readings[index].Distance
                                                                         : std::numeric_limits<double>::quiet_NaN();
}

double vtkVolumeCutNerveMonitor::GetClearance(int index) const
{
  return index >= 0 && index < static_cast<int>(this->Readings.size()) ? this->Readings[index].Clearance
                                                                         : std::numeric_limits<double>::quiet_NaN();
}

int vtkVolumeCutNerveMonitor::GetLevel(int index) const
{
  return index >= 0 && index < static_cast<int>(this->Readings.size()) ? this->Readings[index].Level : NotReady;
}

double vtkVolumeCutNerveMonitor::GetFiringRate(int index) const
{
  return index >= 0 && index < static_cast<int>(this->Readings.size()) ? this->Readings[index].FiringRate : 0.0;
}

int vtkVolumeCutNerveMonitor::GetHighestLevel() const
{
  int highest = NotReady;
  for (const Reading& reading : this->Readings)
  {
    highest = std::max(highest, reading.Level);
  }
  return highest;
}

//------------------------------------------------------------------------------
void vtkVolumeCutNerveMonitor::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  const Internals& internal = *this->Internal;
  os << indent << "Geometry: " << (internal.HasGeometry ? "set" : "not set") << ", spacing " << internal.Spacing[0] << " " << internal.Spacing[1]
     << " " << internal.Spacing[2] << " mm\n";
  os << indent << "Thresholds (mm): silent above " << internal.Silent << ", sparse clicks above " << internal.Sparse << ", bursts above "
     << internal.Bursts << "\n";
  os << indent << "MaximumFiringRate: " << internal.MaximumRate << " /s\n";
  os << indent << "Range: " << this->Range << " mm\n";
  os << indent << "ContactRange: " << this->ContactRange << " mm\n";
  os << indent << "Smoothing: " << this->Smoothing << " voxels\n";
  os << indent << "SampleSpacing: " << this->SampleSpacing << " mm\n";
  os << indent << "Structures: " << internal.Structures.size() << (this->IsBuilt() ? " (built)" : " (not all built)") << "\n";
  for (size_t index = 0; index < internal.Structures.size(); ++index)
  {
    os << indent.GetNextIndent() << internal.Structures[index].Name << ": value " << internal.Structures[index].Value << ", level "
       << GetLevelAsString(this->GetLevel(static_cast<int>(index))) << ", distance " << this->GetDistance(static_cast<int>(index)) << " mm\n";
  }
  os << indent << "MemorySize: " << this->GetMemorySize() << " bytes\n";
  os << indent << "LastBuildTime: " << this->LastBuildTime << " s (longest structure " << this->LastMaximumStructureBuildTime << " s)\n";
  os << indent << "NumberOfLevelChanges: " << this->NumberOfLevelChanges << "\n";
}
