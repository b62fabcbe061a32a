// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutNerveMonitor
 * @brief   A virtual nerve monitor: the tool's distance to each monitored structure, a level and a firing rate.
 *
 * Seed 003 monitors virtual nerves whose firing rate rises as an active
 * drill nears them, as facial-nerve EMG monitors make nerve irritation
 * audible in the operating room. Here each monitored structure (facial
 * nerve, chorda tympani, sigmoid sinus, ...) is a label in an integer image
 * on the anatomy's voxel grid, with a name. Per structure, Build computes a
 * sparse field (vtkVolumeCutNerveMonitorField, 8^3 bricks within Range) of
 * two signed distances (mm, negative inside):
 *
 * - to the structure's smoothed surface (the surface the renderer draws,
 *   vtkVolumeCutLabelSurface, closed across the slices as the shield closes
 *   it): foot points on its sub-voxel zero set, propagated to every voxel,
 *   read by trilinear interpolation. This is the reading, the anatomy's
 *   distance.
 * - to what the shield keeps (vtkVolumeCutProtection keeps the smoothed
 *   interior and every one of the structure's voxels whole), where the cut
 *   stops: the smaller of the smoothed surface's distance and the voxel
 *   cubes', exact (each sample near the cubes keeps its nearest cube; a
 *   query measures to the cubes of the eight samples around it). This is the
 *   clearance. It is exact wherever the cubes are within ContactRange; beyond,
 *   it is the surface distance.
 *
 * A reading, per structure: the clearance, from the tool's surface to what
 * the shield keeps, and the distance from the tool's surface to the
 * structure's smoothed surface while the clearance is positive, the
 * clearance (0 or less) once the tool touches the shield: on coarse slices
 * the cubes stand up to a millimetre out of the smoothed surface and stop
 * the burr there, and the reading then says contact, never "1 mm away".
 * Exact for the spherical burr (the fields at the centre minus the radius);
 * for any vtkVolumeCutTool the least field values over points on the tool's
 * surface, SampleSpacing apart. The level the distance falls in (thresholds
 * in mm, defaults 4, 2 and 1: silent above 4, sparse clicks from 2 to 4,
 * bursts from 1 to 2, continuous below 1, contact at 0 or less) and a firing
 * rate (spikes/s) that rises with proximity: MaximumFiringRate * (1 -
 * distance / silent threshold)^2, the maximum at contact. Beyond Range the
 * field is not stored: the distance is then a lower bound (at least Range),
 * and the level silent.
 *
 * Threads. Configuration (geometry, structures, thresholds) belongs to one
 * thread. Build may run on a worker while any thread measures: the fields
 * are immutable once built, published with the configuration in a snapshot
 * that measurements read without a lock (a structure whose field is not
 * built yet reads as not ready); a haptic tick calling Measure never waits
 * and allocates nothing. Update* and the reading getters are for the thread
 * that owns the object (they keep the last readings and invoke events).
 *
 * Bad input is refused with an error naming it: a matrix with skewed axes,
 * an empty structure or one outside the scan, thresholds out of order.
 */

#ifndef vtkVolumeCutNerveMonitor_h
#define vtkVolumeCutNerveMonitor_h

#include "vtkCommand.h"                 // For the events
#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro
#include "vtkWrappingHints.h"           // For VTK_WRAPEXCLUDE

#include <memory> // For the internals
#include <string> // For structure names
#include <vector> // For readings

class vtkDoubleArray;
class vtkImageData;
class vtkMatrix4x4;
class vtkPoints;
class vtkVolumeCutTool;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutNerveMonitor : public vtkObject
{
public:
  static vtkVolumeCutNerveMonitor* New();
  vtkTypeMacro(vtkVolumeCutNerveMonitor, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Levels
  {
    Silent = 0,
    SparseClicks = 1,
    Bursts = 2,
    Continuous = 3,
    Contact = 4,
    NotReady = -1
  };
  /// "silent", "sparse clicks", "bursts", "continuous", "contact", "not ready".
  static const char* GetLevelAsString(int level);

  enum Events
  {
    /// Update* changed the level of at least one structure (call data: none).
    LevelChangedEvent = vtkCommand::UserEvent + 2550,
    /// Update* took new readings.
    ReadingsModifiedEvent
  };

  /// One structure's reading.
  struct VTK_WRAPEXCLUDE Reading
  {
    /// To the smoothed surface while Clearance > 0, else Clearance.
    double Distance = 0.0;
    /// To what the shield keeps (the smoothed interior and the voxel cubes).
    double Clearance = 0.0;
    double FiringRate = 0.0;
    int Level = NotReady;
  };

  /**
   * The anatomy's voxel grid: dimensions and IJK-to-RAS (any orientation and
   * spacing, axes at right angles). Forgets every structure. False (and an
   * error) for skewed axes, a zero spacing or no voxel.
   */
  bool SetGeometry(const int dimensions[3], vtkMatrix4x4* ijkToRAS);

  /**
   * Monitor the voxels of labels that hold value (an integer image on the
   * anatomy's grid: its extent says which voxels it covers; its origin,
   * spacing and direction are not read), under name. Returns the
   * structure's index, or -1 (and an error naming it) without geometry, for
   * a name already used, an image without one integer component, or no
   * voxel of the value inside the scan (empty or outside it). The field is
   * made by the next Build.
   */
  int AddStructure(const char* name, vtkImageData* labels, int value);
  void RemoveAllStructures();
  int GetNumberOfStructures() const;
  const char* GetStructureName(int index) const;
  /// Index of the structure named name, -1 if none.
  int GetStructureIndex(const char* name) const;

  /**
   * Build the distance fields not built yet, on the calling thread (a
   * worker may call it while others measure). Returns the number built.
   */
  int Build();
  /// Whether every structure's field is built.
  bool IsBuilt() const;
  /// Seconds the last Build took, and the longest one structure took in it.
  vtkGetMacro(LastBuildTime, double);
  vtkGetMacro(LastMaximumStructureBuildTime, double);
  /// Memory of the built fields (bytes).
  size_t GetMemorySize() const;

  /**
   * Thresholds (mm) between the levels: silent above silent, sparse clicks
   * above sparse, bursts above bursts, continuous above 0, contact at 0 or
   * less. Defaults 4, 2, 1. False (and an error), changing nothing, unless
   * silent > sparse > bursts > 0.
   */
  bool SetThresholds(double silent, double sparse, double bursts);
  double GetSilentThreshold() const;
  double GetSparseThreshold() const;
  double GetBurstThreshold() const;

  ///@{
  /// Set/get the firing rate at contact (spikes/s). Default is 200.
  void SetMaximumFiringRate(double rate);
  double GetMaximumFiringRate() const;
  ///@}

  ///@{
  /**
   * Set/get how far from a structure its field is stored (mm); beyond it a
   * measurement gives a lower bound. Default 8 (the silent threshold and a
   * 7 mm burr's radius). Takes effect for fields built afterwards.
   */
  vtkSetClampMacro(Range, double, 0.5, 100.0);
  vtkGetMacro(Range, double);
  ///@}

  ///@{
  /**
   * Set/get how far from a structure's voxel cubes the clearance is exact
   * (mm, at most Range): contact is exact for burrs of a smaller radius. The
   * band of the cubes' distances costs build time and memory. Default 4 (an
   * 8 mm burr). Takes effect for fields built afterwards.
   */
  vtkSetClampMacro(ContactRange, double, 0.5, 100.0);
  vtkGetMacro(ContactRange, double);
  ///@}

  ///@{
  /**
   * Set/get the in-slice Gaussian (voxels) that smooths the structures'
   * surfaces, as the renderer's LabelSmoothing and the shield's
   * SurfaceSmoothing; 0: the voxel cubes alone, as the shield then is.
   * Default 1. Takes effect for fields built afterwards.
   */
  vtkSetClampMacro(Smoothing, double, 0.0, 8.0);
  vtkGetMacro(Smoothing, double);
  ///@}

  ///@{
  /**
   * Set/get the spacing (mm) of the points on a tool's surface where
   * MeasureTool reads the fields. Default 0.2. Takes effect at the next PrepareTool.
   */
  vtkSetClampMacro(SampleSpacing, double, 0.02, 5.0);
  vtkGetMacro(SampleSpacing, double);
  ///@}

  /// Level of a distance (mm) under the current thresholds.
  int GetLevelOfDistance(double distance) const;
  /// Firing rate (spikes/s) at a distance (mm).
  double GetFiringRateOfDistance(double distance) const;

  /**
   * Signed distance (mm) from a RAS point to a structure's smoothed surface
   * (negative inside); a lower bound beyond Range; NaN before its field is
   * built or for an unknown index.
   */
  double GetDistanceAt(int index, const double ras[3]) const;
  /// As GetDistanceAt, to what the shield keeps (the smoothed interior and the voxel cubes).
  double GetClearanceAt(int index, const double ras[3]) const;

  /**
   * Any thread, never waits, allocates nothing: readings for the spherical
   * burr of the given radius centred at centre (RAS) into readings (one per
   * structure, up to capacity). Returns the number of structures.
   */
  VTK_WRAPEXCLUDE int Measure(const double centre[3], double radius, Reading* readings, int capacity) const;

  /**
   * Measure for a burr of radius at each of centres (RAS), as Measure: the
   * distances (one tuple of GetNumberOfStructures components per centre)
   * into distances and, unless nullptr, each measurement's duration (us)
   * into microseconds and the processor time this thread spent in it (us)
   * into processorMicroseconds: a trajectory's readings, and the per-tick
   * cost from Python. A duration far above its processor time is time the
   * thread was not running (preempted), not the measurement's cost. False
   * (and an error) without centres or distances.
   */
  bool MeasureAlong(vtkPoints* centres, double radius, vtkDoubleArray* distances, vtkDoubleArray* microseconds,
    vtkDoubleArray* processorMicroseconds = nullptr);

  /**
   * Points on tool's surface (its frame) where MeasureTool reads, made on
   * the calling thread (the owner's). False (and an error) for an invalid tool.
   */
  bool PrepareTool(vtkVolumeCutTool* tool);
  /// The number of points PrepareTool placed on the tool.
  int GetNumberOfToolSamples() const;
  /**
   * As Measure, for the tool last prepared placed by toolToRAS (16 values,
   * row-major). Returns -1 if no tool was prepared.
   */
  VTK_WRAPEXCLUDE int MeasureTool(const double toolToRAS[16], Reading* readings, int capacity) const;

  ///@{
  /**
   * The owner's thread: take readings (for the burr, for a tool, or given
   * ones, e.g. taken on a haptic thread) as the current ones, and invoke
   * LevelChangedEvent if a level changed and ReadingsModifiedEvent. False
   * (and an error) for an invalid tool.
   */
  void UpdateWithBurr(const double centre[3], double radius);
  bool UpdateWithTool(vtkVolumeCutTool* tool, vtkMatrix4x4* toolToRAS);
  VTK_WRAPEXCLUDE void UpdateWithReadings(const Reading* readings, int count);
  ///@}

  ///@{
  /// The current readings of structure index (NaN, 0 and NotReady before any).
  double GetDistance(int index) const;
  double GetClearance(int index) const;
  int GetLevel(int index) const;
  double GetFiringRate(int index) const;
  /// The highest level over the structures (NotReady if none is ready).
  int GetHighestLevel() const;
  /// How many updates changed a level.
  vtkGetMacro(NumberOfLevelChanges, int);
  ///@}

protected:
  vtkVolumeCutNerveMonitor();
  ~vtkVolumeCutNerveMonitor() override;

  struct Internals;
  std::unique_ptr<Internals> Internal;
  /// Both distances of structure index at a RAS point; false before its field is built or for an unknown index.
  bool GetDistancesAt(int index, const double ras[3], double& surface, double& shield) const;

  double Range = 8.0;
  double ContactRange = 4.0;
  double Smoothing = 1.0;
  double SampleSpacing = 0.2;
  double LastBuildTime = 0.0;
  double LastMaximumStructureBuildTime = 0.0;
  int NumberOfLevelChanges = 0;
  std::vector<Reading> Readings;

private:
  vtkVolumeCutNerveMonitor(const vtkVolumeCutNerveMonitor&) = delete;
  void operator=(const vtkVolumeCutNerveMonitor&) = delete;
};

#endif
