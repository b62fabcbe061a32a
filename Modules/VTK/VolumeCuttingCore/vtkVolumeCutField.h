// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutField
 * @brief   The removed region of a cutting session, at sub-voxel resolution.
 *
 * Multivolume scheme of Pflesser et al. (2002): the anatomy is never changed;
 * what the tools remove lives in this separate field, aligned with the
 * anatomy's voxel grid (any spacing, any IJK-to-RAS orientation) and refined
 * by a sub-voxel factor of 1, 2 or 4 along each axis.
 *
 * Representation: a narrow-band signed distance to the boundary of the
 * removed region, in millimetres, negative inside (removed), sampled at
 * sub-voxel centres and clamped to +-BandWidth. A cut is the union of the
 * removed region with the tool's swept volume, which on distances is a
 * minimum: it resamples the existing cut and the new tool together, as
 * progressive cutting requires, and it is exact, associative and idempotent,
 * so many small overlapping strokes give the same field as one large stroke,
 * without erosion or drift. Restoring material (seed 004's adding) is the
 * maximum with the negated tool distance. The partial-volume (filtered)
 * removed fraction of any sample follows from its distance.
 *
 * Storage is sparse: 8x8x8 bricks, allocated only where a tool came within the
 * band. Each brick carries a modification stamp, so a renderer uploads and
 * re-renders only what changed since the stamp it last saw.
 *
 * Threads: one writer (the haptic or interaction thread) calls the cut,
 * restore and undo methods; any number of readers may call the query methods
 * at the same time. The writer never waits: bricks are published once and
 * never freed while the field lives, and each brick has a sequence counter
 * that readers check to retry a read that overlapped a write.
 */

#ifndef vtkVolumeCutField_h
#define vtkVolumeCutField_h

#include "vtkObject.h"
#include "vtkType.h" // For vtkTypeUInt64
#include "vtkSmartPointer.h"              // For the protection and the undo history
#include "vtkVolumeCutProtection.h"     // For the protection
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <atomic>  // For the brick directory
#include <cstdint> // For int16_t
#include <map>     // For BrickStates
#include <memory>  // For std::unique_ptr
#include <vector>  // For the brick directory

class vtkFloatArray;
class vtkIdList;
class vtkIdTypeArray;
class vtkImageData;
class vtkMatrix4x4;
class vtkPolyData;
class vtkVolumeCutFieldUndoHistory;
class vtkVolumeCutTool;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutField : public vtkObject
{
public:
  static vtkVolumeCutField* New();
  vtkTypeMacro(vtkVolumeCutField, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Edge length of a brick, in sub-voxels.
  static constexpr int BrickSize = 8;

  /**
   * Align the field with an anatomy volume of the given dimensions and
   * IJK-to-RAS matrix, at a sub-voxel factor of 1, 2 or 4. Everything cut so
   * far and the undo history are discarded. Returns false and logs an error,
   * leaving the field as it was, for non-positive dimensions, a factor other
   * than 1, 2 or 4, a matrix that is not finite or not invertible, or more
   * than 2^31 bricks.
   */
  bool Initialize(const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS, int subVoxelFactor);

  /**
   * Write the field (geometry, band and every allocated brick; not the undo
   * history or the protection, which follow from the session) to a file.
   * Returns false and logs an error if it cannot be written.
   */
  bool WriteFile(const char* fileName) const;

  /**
   * Read a field written by WriteFile. A missing, truncated, corrupt or
   * foreign file is refused with an error and leaves this field as it was.
   */
  bool ReadFile(const char* fileName);

  /// Make this field a copy of another: geometry and samples, not history.
  void DeepCopy(vtkVolumeCutField* source);

  ///@{
  /**
   * Geometry of the sub-voxel grid (valid after Initialize).
   */
  vtkGetVector3Macro(Dimensions, int);
  vtkGetMacro(SubVoxelFactor, int);
  void GetSubVoxelIJKToRAS(vtkMatrix4x4* matrix) const;
  /// Sub-voxel edge lengths in mm along the three grid axes.
  void GetSubVoxelSpacing(double spacing[3]) const;
  ///@}

  ///@{
  /**
   * Set/get the half width (mm) of the band in which distances are stored.
   * It must cover the diagonal of a sub-voxel and its neighbours; Initialize sets it to 3.5 times
   * the largest sub-voxel spacing. Farther samples are clamped.
   */
  vtkGetMacro(BandWidth, double);
  ///@}

  ///@{
  /**
   * Set/get the longest stroke (mm) accepted as one continuous sweep. A longer
   * jump between two poses (a tracking glitch, a device reconnected
   * elsewhere) is rejected with an error instead of carving a channel through
   * the anatomy. Default is 50 mm.
   */
  vtkSetClampMacro(MaximumStrokeLength, double, 0.0, 1.0e6);
  vtkGetMacro(MaximumStrokeLength, double);
  ///@}

  /**
   * Remove the volume swept by a sphere of the given radius (mm) moving from
   * p0 to p1 (RAS, mm): a capsule, or a sphere when p0 equals p1. This is the
   * continuous sweep of a spherical burr between two poses, so fast strokes
   * leave no gaps. Returns false and logs an error, changing nothing, for a
   * non-finite pose, a radius that is not positive, or a stroke longer than
   * MaximumStrokeLength. A tool wholly outside the volume changes nothing and
   * returns true. Each successful call is one undo step.
   */
  bool CutCapsule(const double p0[3], const double p1[3], double radius);

  /**
   * Put back removed material inside the capsule (restore brush): the
   * removed region loses the tool's swept volume. Same validation as
   * CutCapsule; one undo step.
   */
  bool RestoreCapsule(const double p0[3], const double p1[3], double radius);

  /**
   * Remove the volume swept by any tool (vtkVolumeCutTool: cylinder or disk,
   * ellipsoid, box or blade, closed mesh) moving rigidly from pose0 to pose1
   * (tool-to-RAS matrices, mm). Between the poses the tool is placed at
   * intermediate poses (linear translation, spherical rotation) no farther
   * apart than half a sub-voxel at any point of the tool, so the sweep has no
   * gaps. Returns false and logs an error, changing nothing, for an invalid
   * tool, a pose that is not finite or not rigid, or a jump longer than
   * MaximumStrokeLength. One undo step outside a stroke.
   */
  bool CutToolSweep(vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);

  /// Put back removed material inside the tool's sweep (as CutToolSweep).
  bool RestoreToolSweep(vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);

  /**
   * Remove a region given as signed distances (mm, negative inside) sampled
   * at the anatomy's voxel centres, such as a planned soft-tissue resection
   * (vtkVolumeCutResectionPlanner). distances: a float or double image whose
   * extent names the anatomy voxels it covers (as the shield's label images:
   * origin, spacing and direction are not read); with several components the
   * region is where all of them are negative, and the distance at a point is
   * the largest of the trilinearly interpolated components, so the crease
   * where two of them meet stays sharp. Nothing is removed outside the image.
   * keep, if given: an integer image on the anatomy's voxels (any extent)
   * whose positive voxels are never removed: the region stays half a
   * sub-voxel away from their cubes, so that not even the partial-volume
   * fraction of its surface (GetRemovedFraction) reaches them. The field's own shield applies as for any tool, contacts
   * included. Returns false and logs an error, changing nothing, for a field
   * that is not initialized or images without usable scalars. One undo step
   * outside a stroke.
   */
  bool CutSampledRegion(vtkImageData* distances, vtkImageData* keep = nullptr);

  ///@{
  /**
   * Group the cuts and restores between BeginStroke and EndStroke into one
   * undo step: a user's stroke is many device poses (a thousand a second from
   * a haptic device), undone together. Calls outside a stroke are one step
   * each. EndStroke without BeginStroke does nothing.
   */
  void BeginStroke();
  void EndStroke();
  bool IsStrokeOpen() const;
  ///@}

  ///@{
  /**
   * Undo or redo one stroke (an open stroke is ended first). Return false (and log an error) when there is
   * nothing to undo or redo.
   */
  bool Undo();
  bool Redo();
  int GetNumberOfUndoSteps() const;
  int GetNumberOfRedoSteps() const;
  ///@}

  ///@{
  /**
   * Set/get the memory (bytes) the undo history may use. When a stroke would
   * exceed it, the oldest steps are dropped and a warning says how many; a
   * single stroke larger than the budget cannot be undone (error). Default is
   * 256 MiB. GetUndoMemorySize reports what the history uses now.
   */
  vtkSetMacro(UndoMemoryBudget, size_t);
  vtkGetMacro(UndoMemoryBudget, size_t);
  size_t GetUndoMemorySize() const;
  ///@}

  /**
   * The shield: the structures a tool must not remove (tool "sensibility",
   * Pflesser et al.). Give it label images and say which of their values are
   * shielded (vtkVolumeCutProtection); it is built brick by brick where tools
   * reach. The removed region becomes the tool's sweep minus the shielded
   * structures, bounded by their smoothed surface (or their voxel cubes,
   * sharp edges included: SetSurfaceSmoothing(0)) and never entering a
   * shielded voxel, and a tool entering a shielded
   * structure is reported as a contact. Cuts already made are not changed by
   * a new shield. Always present; it follows the field's geometry and is
   * emptied by Initialize. Change it only while no stroke is being written.
   */
  vtkVolumeCutProtection* GetProtection() { return this->Protection; }

  /**
   * Build the shield where a tool at center (RAS) with the given reach (mm)
   * could cut next, so that its first strokes there find it built: call it
   * while the tool hovers, from the writer's thread. Returns the number of
   * bricks built.
   */
  vtkIdType PrepareProtection(const double center[3], double radius);

  /**
   * Build the same bricks as PrepareProtection on the calling thread, which
   * is not the writer's, while the writer may cut: the writer finds them
   * built when it reaches them, without waiting (vtkVolumeCutProtection::PrepareBricks). For a writer with a deadline:
   * the haptic thread's preparer calls it around the tool. Not while the
   * field's geometry or the shield's images or table change. Returns the
   * number of bricks built.
   */
  vtkIdType PrepareProtectionAhead(const double center[3], double radius);

  /**
   * Shield structures given as one label image with the anatomy's dimensions
   * (IJK geometry; one integer component): 0 for voxels a tool may cut, k > 0
   * for the k-th protected structure (labels above 255 are reported as 255).
   * Replaces the protection's images and table; nullptr clears them. Returns
   * false (and an error), changing nothing, if the dimensions differ.
   */
  bool SetProtectedLabels(vtkImageData* labels);

  /**
   * Replace this field's samples by another field's cut resampled onto this
   * field's grid (after Initialize with the new grid or factor): every sample
   * takes the other field's signed distance at its position, so the removed
   * region is kept to within the coarser grid's accuracy. The undo history
   * starts empty. Returns false (and an error), changing nothing, if either
   * field is not initialized. Where both grids are the same lattice indexed
   * another way (axes flipped or swapped, as readers reorient scans), the
   * samples are copied exactly instead (see IsSameLattice).
   */
  bool ResampleFrom(vtkVolumeCutField* source);

  /**
   * Whether another initialized field's samples lie exactly where this
   * field's do (to a thousandth of a sample), whatever the order of their
   * axes: then ResampleFrom copies them bit for bit.
   */
  bool IsSameLattice(vtkVolumeCutField* other);

  /// Includes changes of the shield, which change what exports report.
  vtkMTimeType GetMTime() override;

  ///@{
  /**
   * Contacts with protected structures since the last ResetContact(): the
   * deepest penetration (mm) of a tool into protected voxels, the structure's
   * label (0 if none) and where (RAS). A contact removes nothing.
   */
  vtkGetMacro(MaximumContactDepth, double);
  vtkGetMacro(ContactLabel, int);
  vtkGetVector3Macro(ContactPosition, double);
  void ResetContact();
  ///@}

  /**
   * Signed distance (mm) to the boundary of the removed region at a RAS
   * point, trilinearly interpolated with a curvature correction from the
   * samples' second differences; negative where removed. Points outside
   * the band or the volume return +BandWidth. Safe to call while a writer cuts.
   * Where the interpolated distance exceeds GetCorrectionReach() the
   * correction (at most a quarter of the sum of the sub-voxel spacings) is
   * left out: it cannot change the sign there, and the renderers, which
   * evaluate distances at every ray sample inside the anatomy, then need 8
   * samples instead of 56.
   */
  double GetSignedDistance(const double ras[3]) const;

  /// Distance (mm) from the surface within which GetSignedDistance is corrected for curvature.
  vtkGetMacro(CorrectionReach, double);

  /**
   * Removed fraction (0..1) of the sub-voxel (i, j, k): the partial-volume
   * (filtered) value of the removed region. Cells the surface crosses are
   * integrated over 4^3 points of the reconstructed distance, each with a
   * ramp as wide as a sub-cell's extent along the surface normal. A sample
   * inside a shielded voxel that the field did not remove (its distance is
   * not negative) is exactly 0: the shield's voxel cube is outside the removed
   * region, though the ramp of the cut surface on its face would spill into it.
   */
  double GetRemovedFraction(int i, int j, int k) const;

  /**
   * Copy one brick's samples (BrickSize^3 values, x fastest; the distance in
   * mm is value * GetQuantum()) consistently even while the writer changes
   * it, and return the brick's stamp (0 for a brick never written, whose
   * samples are all +BandWidth). For renderers uploading changed bricks.
   */
  vtkTypeUInt64 CopyBrick(vtkIdType brickId, short* values) const;

  /// Distance (mm) of one unit of the stored samples.
  vtkGetMacro(Quantum, double);

  /// Total removed volume (mm^3): the sum of removed fractions.
  double ComputeRemovedVolume() const;

  /**
   * Fraction removed (0..1) of each anatomy voxel, as a float image with the
   * anatomy's dimensions and IJK geometry (origin 0, spacing 1: the anatomy
   * node gives IJK-to-RAS), the mean of its sub-voxels' removed fractions.
   */
  void ExportRemovedFraction(vtkImageData* anatomyFraction) const;

  /**
   * The same fractions for only the anatomy voxels with a removed fraction
   * above zero: their linear index (i + dims[0] * (j + dims[1] * k)) and
   * fraction, in the order of the allocated bricks. The cost follows the
   * cut, not the volume: for per-segment volumes on patient-scale scans.
   */
  void ExportRemovedVoxels(vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const;

  /**
   * Append the removed voxels of one brick (the anatomy voxels it holds: a
   * brick spans whole anatomy voxels) to the arrays, as ExportRemovedVoxels
   * does. A brick's fractions read the samples of its 26 neighbours too: for
   * incremental tallies (vtkVolumeCutRemovedVoxels).
   */
  void AppendRemovedVoxelsOfBrick(vtkIdType brickId, vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const;

  /**
   * The boundary of the removed region as a closed triangle surface in RAS
   * (mm), contoured at sub-voxel resolution from the distance samples (flying
   * edges at distance 0). Empty if nothing is removed. For STL export and for
   * showing the removed volume as a model.
   */
  void ExtractRemovedSurface(vtkPolyData* surface) const;

  ///@{
  /**
   * Modification stamps. Every change to a brick gives it a new stamp, larger
   * than any before. A renderer keeps the current stamp and later asks which
   * bricks changed since then.
   */
  vtkTypeUInt64 GetCurrentStamp() const { return this->StampCounter.load(std::memory_order_acquire); }
  void GetBricksModifiedSince(vtkTypeUInt64 stamp, vtkIdList* brickIds) const;
  /// The stamp of one brick (0 if never written).
  vtkTypeUInt64 GetBrickStamp(vtkIdType brickId) const;
  vtkGetVector3Macro(BrickDimensions, int);
  ///@}

  ///@{
  /**
   * Memory in use by allocated bricks (bytes), their number, and the memory
   * a dense field of the same resolution would need.
   */
  vtkIdType GetNumberOfAllocatedBricks() const { return this->NumberOfAllocatedBricks.load(std::memory_order_acquire); }
  /// The ID of the n-th allocated brick (in allocation order), -1 out of range.
  vtkIdType GetAllocatedBrickId(vtkIdType n) const
  {
    return n >= 0 && n < this->GetNumberOfAllocatedBricks() ? this->AllocatedBrickIds[n].load(std::memory_order_relaxed) : -1;
  }
  size_t GetBrickMemorySize() const;
  size_t GetDenseMemorySize() const;
  ///@}

  /// Instruction sets of the writer's per-sample loops.
  enum InstructionSetType
  {
    InstructionSetBaseline = 0, ///< what the compiler targets by default
    InstructionSetAVX2,
    InstructionSetAVX512
  };

  ///@{
  /**
   * The instruction set the writer's loops use, for the whole process: the
   * widest this build and processor have, unless set here. Every set gives
   * bitwise the same field, so switching is safe at any time; it is here so
   * that benchmarks and tests can compare them. SetInstructionSet returns
   * false, changing nothing, for a set this build or processor lacks.
   */
  static bool SetInstructionSet(int set);
  static int GetInstructionSet();
  static bool IsInstructionSetAvailable(int set);
  static const char* GetInstructionSetAsString(int set);
  ///@}

protected:
  vtkVolumeCutField();
  ~vtkVolumeCutField() override;

  struct Brick;

public:
  /// Internal: a tool sweep's reach and distances, written row by row or a
  /// brick at a time (vtkVolumeCutFieldDistanceSource.h).
  struct DistanceSource;
  struct RowDistanceSource;
  struct BrickDistanceSource;

protected:
  enum class Operation
  {
    Cut,
    Restore
  };

  using BrickValues = std::vector<int16_t>;
  /// Whole bricks' values by brick ID.
  using BrickStates = std::map<vtkIdType, BrickValues>;

  /// Samples [Start, Start + Count) of a brick that a merge changed.
  struct ChangedRun
  {
    int Start;
    int Count;
  };

  bool ApplyCapsule(const double p0[3], const double p1[3], double radius, Operation operation);
  void ApplyDistance(const RowDistanceSource& source, Operation operation);
  void ApplyDistance(const BrickDistanceSource& source, Operation operation);
  /// The sub-voxel index box of a source's reach; false when it misses the volume.
  bool GetReachIndexRange(const DistanceSource& source, int lower[3], int upper[3]) const;
  /// Runs write(lower, upper) over a source's reach within a stroke (its own
  /// unless one is open); write returns whether it changed anything.
  template <typename Writer>
  void ApplyWithinStroke(const DistanceSource& source, Writer&& write);
  bool ApplyRowwise(const RowDistanceSource& source, Operation operation, const int lower[3], const int upper[3]);
  bool ApplyBrickwise(const BrickDistanceSource& source, Operation operation, const int lower[3], const int upper[3]);
  /// Narrows a brick's z-slices firstSlice..lastSlice to those the source's
  /// bounds say may change; false when none may.
  bool TrimSlices(const BrickDistanceSource& source, const double origin[3], const Brick* brick, const vtkVolumeCutProtection::Brick* protection,
    Operation operation, int& firstSlice, int& lastSlice) const;
  void QuantizeDistances(const float* distances, int count, Operation operation, int16_t* quantized) const;
  /// Merges a run of quantised tool distances into a brick (null: not
  /// allocated) at sample rowStart; records contacts with protected samples.
  bool MergeSegment(const Brick* brick, const vtkVolumeCutProtection::Brick* protection, const int brickIndex[3], const int16_t* quantized, int rowStart,
    int count, Operation operation, const DistanceSource& source, int16_t* merged);
  /// Stores the changed runs of merged (a whole brick's layout) under the
  /// brick's seqlock, remembering the brick for undo first.
  void CommitBrick(vtkIdType brickId, Brick* brick, const int16_t* merged, const ChangedRun* runs, int runCount);
  bool ApplyToolSweep(vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1, Operation operation);
  bool ValidateStroke(const double p0[3], const double p1[3], double radius, const char* caller) const;
  Brick* GetOrCreateBrick(vtkIdType brickId);
  void WriteBricks(const BrickStates& bricks);
  /// Write bricks as the whole new content of a field made from another (no history).
  void ReplaceBricks(const BrickStates& bricks);
  /// The brick's (i, j, k) in the brick grid.
  void GetBrickIndex(vtkIdType brickId, int index[3]) const;
  int16_t ReadSample(int i, int j, int k) const;
  double InterpolateAtIndex(const double index[3]) const;
  /// The interpolation of InterpolateAtIndex over samples given by read(i, j, k).
  template <typename SampleReader>
  double Interpolate(const double index[3], SampleReader&& read) const;
  /// ResampleFrom's exact path: false, changing nothing, unless the grids are one lattice.
  bool CopyFromSameLattice(vtkVolumeCutField* source);
  /// The signed permutation and offset taking this field's indices to the other's, if one lattice.
  bool GetLatticeMap(vtkVolumeCutField* source, int permutation[3][3], int offset[3]) const;
  /// The removed fraction of a sample from the field alone (no shield).
  double ComputeRemovedFraction(int i, int j, int k) const;
  /// Calls visit(i, j, k, shielded) for every sample of a brick; shielded:
  /// the sample's anatomy voxel is in a shielded structure.
  template <typename Visitor>
  void ForEachSampleOfBrickWithShield(vtkIdType brickId, Visitor&& visit) const;
  void Reset();
  /// The shield of a brick (built on first reach), nullptr where the tool cuts freely.
  const vtkVolumeCutProtection::Brick* GetProtectionBrick(vtkIdType brickId);
  /// The bricks whose shield a tool at center with the given reach may need; false if there is no shield.
  bool CollectProtectionBricks(const double center[3], double radius, std::vector<vtkIdType>& brickIds) const;
  /// PrepareProtection's list, kept between calls (writer only).
  std::vector<vtkIdType> PreparationBrickIds;

  int Dimensions[3] = { 0, 0, 0 };
  int BrickDimensions[3] = { 0, 0, 0 };
  int SubVoxelFactor = 0;
  double BandWidth = 1.0;
  double Quantum = 1.0 / 32767.0;
  double HalfDiagonal = 0.5;
  double CorrectionReach = 1.0;

  /// The last capsule cut, valid while nothing else has changed the field
  /// (its stamp), the protection or the contact record: a capsule that
  /// starts where it ended need not recompute the half ball behind its
  /// start, which the last one already cut with the same distances.
  /// Consecutive segments of a drill path are such capsules.
  struct CapsuleContinuation
  {
    bool Valid = false;
    double End[3] = { 0.0, 0.0, 0.0 };
    double Radius = 0.0;
    vtkTypeUInt64 Stamp = 0;
    vtkMTimeType ProtectionTime = 0;
  };
  CapsuleContinuation LastCapsule;
  /// The same for the last tool sweep: a sweep that starts at the pose where
  /// the last one ended, with the same tool, need not cut its first pose again.
  struct ToolSweepContinuation
  {
    bool Valid = false;
    vtkVolumeCutTool* Tool = nullptr;
    vtkMTimeType ToolTime = 0;
    /// Rotation (tool-to-RAS) and translation of the last pose.
    struct
    {
      double Rotation[3][3];
      double Translation[3];
    } End = {};
    vtkTypeUInt64 Stamp = 0;
    vtkMTimeType ProtectionTime = 0;
  };
  ToolSweepContinuation LastToolSweep;
  double MaximumStrokeLength = 50.0;
  double SubIJKToRAS[4][4];
  double AnatomyIJKToRAS[16];
  double RASToSubIJK[4][4];
  size_t UndoMemoryBudget = 256u << 20;

  std::unique_ptr<std::atomic<Brick*>[]> Directory;
  // Allocated brick IDs in allocation order; readers see the first
  // NumberOfAllocatedBricks entries.
  std::unique_ptr<std::atomic<vtkIdType>[]> AllocatedBrickIds;
  std::atomic<vtkIdType> NumberOfAllocatedBricks{ 0 };
  std::vector<std::unique_ptr<Brick>> OwnedBricks;
  vtkSmartPointer<vtkVolumeCutProtection> Protection;
  double MaximumContactDepth = 0.0;
  int ContactLabel = 0;
  double ContactPosition[3] = { 0.0, 0.0, 0.0 };

  // Writer's scratch: quantised tool distances of the rows of one line of bricks.
  std::vector<int16_t> RowScratch;
  std::vector<float> DistanceScratch;
  // RAS offsets of a brick's samples from its first (x, then y, then z, each
  // SamplesPerBrick long) and the radius of a ball about its centre holding them.
  std::vector<float> BrickSampleOffsets;
  double BrickBoundingRadius = 0.0;
  std::atomic<vtkTypeUInt64> StampCounter{ 0 };
  /// The strokes that can be undone and redone, and the open one.
  vtkSmartPointer<vtkVolumeCutFieldUndoHistory> History;

private:
  friend class vtkVolumeCutMaterialRemoval;
  friend class vtkVolumeCutFieldFile;
  friend class vtkVolumeCutFieldUndoHistory;
  vtkVolumeCutField(const vtkVolumeCutField&) = delete;
  void operator=(const vtkVolumeCutField&) = delete;
};

#endif
