// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutProtection
 * @brief   The shield of a cut field: the structures a tool must not remove.
 *
 * Tool "sensibility" (Pflesser et al., 2002): a tool removes only what it may
 * cut; the anatomy voxels of every other structure are shielded. The shield
 * is a signed distance (mm, negative inside) sampled at the cut field's
 * sub-voxel centres within its band; the writer cuts max(tool, -shield).
 * By default its zero is the structures' smoothed surface, the one the
 * renderer draws for segments known only as voxels (vtkVolumeCutSliceDistance:
 * in-slice distance to the outline, smoothed by a Gaussian of
 * SurfaceSmoothing voxels, interpolated between slices), so that the wall a
 * burr leaves against a structure is as smooth as that surface, not a
 * lattice of voxel steps. Where that surface passes inside a shielded voxel,
 * the voxel's samples stay shielded all the same (by one quantum): nothing
 * inside a shielded voxel is ever removed. With SurfaceSmoothing 0 the shield
 * is the exact distance to the union of the shielded voxel cubes, and creases
 * are exact to the voxel faces.
 *
 * Where the shielded voxels are is read from label images on the anatomy's
 * voxel grid: Slicer's segmentation layers, in which several segments share
 * one image with different values. Which value of which image is shielded,
 * and as which structure, is a small table, so that changing roles costs
 * nothing in proportion to the volume.
 *
 * The shield is built a brick at a time, the first time a tool reaches the
 * brick, from the labels around it (the smoothed surface: the slices' exact
 * distance transforms within a window wide enough that every brick finds
 * the same surface; the voxel cubes: a separable minimum over the three
 * axes, exact, not an approximation of the distance to the cubes). Nothing is computed for the parts of a patient-scale scan that no
 * tool comes near, and a role change only forgets the bricks built so far.
 *
 * Threads: the images and the table are changed, and bricks are built, by the
 * field's writer (or while no writer runs); GetShieldLabel may be called by
 * readers while the writer cuts, provided the images and the table do not change.
 * Another thread may build bricks ahead of the writer (PrepareBricks) while
 * the writer cuts. Built bricks are published in a directory of atomic
 * pointers, one a brick of the field: whoever builds a brick first puts it
 * there, the other drops its copy. A writer with a deadline (the haptic
 * thread) thus never waits for a preparation and never moves what was
 * prepared: it finds built what was prepared in time, and builds the rest
 * itself, as without a preparer.
 */

#ifndef vtkVolumeCutProtection_h
#define vtkVolumeCutProtection_h

#include "vtkObject.h"
#include "vtkSmartPointer.h"            // For the label images
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <cstdint>       // For uint8_t
#include <atomic> // For the brick directory
#include <memory> // For std::unique_ptr
#include <mutex>  // For serialising preparers
#include <vector> // For the label images

class vtkImageData;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutProtection : public vtkObject
{
public:
  static vtkVolumeCutProtection* New();
  vtkTypeMacro(vtkVolumeCutProtection, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The largest value a label image may use for a shielded segment.
  static constexpr int MaximumLabelValue = 65535;

  /**
   * Add an integer image on the anatomy's voxel grid whose values name
   * segments (0: none). Its extent says which anatomy voxels it covers
   * (voxels outside hold no segment); origin, spacing and direction are not
   * read. Returns its index for SetShieldLabel, or -1 (and an error) for an
   * image without one integer scalar component.
   */
  int AddLabelImage(vtkImageData* image);
  int GetNumberOfLabelImages() const { return static_cast<int>(this->LabelImages.size()); }
  vtkImageData* GetLabelImage(int index) const;
  /// Remove every label image and the whole table.
  void RemoveAllLabelImages();

  /**
   * Shield the voxels that hold value in the label image as structure label
   * (1..255; 0 unshields them). Where shielded voxels of several structures
   * overlap, the highest label names the voxel. Returns false (and an error),
   * changing nothing, for an unknown image, a value outside 1..MaximumLabelValue
   * or a label outside 0..255.
   */
  bool SetShieldLabel(int imageIndex, int value, int label);
  /// Unshield everything, keeping the images.
  void RemoveAllShieldLabels();
  /// Whether any value of any image is shielded.
  bool HasShieldedLabels() const;

  /**
   * The structure label (0: not shielded) of anatomy voxel (i, j, k); voxels
   * outside the anatomy are not shielded.
   */
  int GetShieldLabel(int i, int j, int k) const;

  /**
   * Labels of the anatomy voxels of a box (inclusive bounds, any part may lie
   * outside the anatomy: those voxels are 0), x fastest, into labels.
   */
  void GetShieldLabels(const int voxelLower[3], const int voxelUpper[3], uint8_t* labels) const;

  /**
   * Geometry of the cut field the shield is sampled for: anatomy dimensions,
   * sub-voxel factor, the anatomy's spacing along its three grid axes, and
   * the field's band and quantum. Set by vtkVolumeCutField; forgets the
   * bricks built so far.
   */
  void SetFieldGeometry(const int anatomyDimensions[3], int subVoxelFactor, const double anatomySpacing[3], double bandWidth, double quantum);

  /**
   * Width (anatomy voxels, 0..8) of the in-slice Gaussian that smooths the
   * shielded structures' surface, as vtkVolumeCutRayCaster::SetLabelSmoothing
   * does for the surface it draws: the same value gives the wall a tool
   * leaves against a structure the surface drawn for it. 0: the voxel cubes,
   * stairs included. Either way nothing inside a shielded voxel is removed.
   * Forgets the bricks built so far (not while the writer cuts). Default 1.
   */
  void SetSurfaceSmoothing(double sigma);
  vtkGetMacro(SurfaceSmoothing, double);

  /// Internal: the shield within one brick of the field (vtkVolumeCutProtectionBrick.h).
  struct Brick;

  /**
   * The shield within a brick of the field, built on first request; nullptr
   * where no shielded voxel lies within the band (the tool cuts freely).
   */
  const Brick* GetBrick(vtkIdType brickId);

  ///@{
  /// Bricks built so far (those with a shield and those found free) and the memory they use.
  vtkIdType GetNumberOfBuiltBricks() const { return this->BuiltBricks.load(std::memory_order_acquire); }
  vtkIdType GetNumberOfShieldBricks() const { return this->ShieldBricks.load(std::memory_order_acquire); }
  size_t GetMemorySize() const;
  ///@}

  /**
   * Bricks GetBrick had to build itself because no preparation had built
   * them (the cost a writer with a deadline must not pay; writer's thread),
   * and bricks built by PrepareBricks (with or without a shield). Counted
   * since SetFieldGeometry or ClearBricks.
   */
  vtkIdType GetNumberOfBricksBuiltOnDemand() const { return this->BricksBuiltOnDemand; }
  vtkIdType GetNumberOfPreparedBricks() const { return this->PreparedBricks.load(std::memory_order_acquire); }

  /**
   * Build the given bricks on the calling thread, skipping those built
   * already, for the writer to find built when it reaches them. Safe while
   * the writer cuts (not while the images, the table or the geometry
   * change). Calls from several threads are serialised. Returns the number
   * of bricks built.
   */
  vtkIdType PrepareBricks(const vtkIdType* brickIds, vtkIdType count);

  /// Forget the bricks built so far (they are built again when reached). Not while the writer cuts; waits for a preparation.
  void ClearBricks();

protected:
  vtkVolumeCutProtection();
  ~vtkVolumeCutProtection() override;

  struct Scratch;
  /// Builds the shield of one brick in scratch's working memory; nullptr where it would be free.
  std::unique_ptr<Brick> BuildBrick(vtkIdType brickId, Scratch& scratch) const;
  /// The shield of the voxel cubes (SurfaceSmoothing 0), and the nearest structure of every sample.
  std::unique_ptr<Brick> BuildVoxelFaceBrick(vtkIdType brickId, Scratch& scratch) const;
  /// The shield of the smoothed surface (SurfaceSmoothing > 0).
  std::unique_ptr<Brick> BuildSmoothedBrick(vtkIdType brickId, Scratch& scratch) const;
  /**
   * Put a brick just built (nullptr: free) into the directory unless the
   * other side did first; returns the brick the directory holds then
   * (nullptr: free). Counts it if it went in.
   */
  const Brick* Publish(vtkIdType brickId, std::unique_ptr<Brick> built);
  /// Free every built brick and empty the directory.
  void ReleaseBricks();

  struct LabelImage
  {
    vtkSmartPointer<vtkImageData> Image;
    /// Structure label by voxel value (0: not shielded).
    std::vector<uint8_t> Labels;
  };
  std::vector<LabelImage> LabelImages;

  int AnatomyDimensions[3] = { 0, 0, 0 };
  int BrickDimensions[3] = { 0, 0, 0 };
  int SubVoxelFactor = 0;
  double AnatomySpacing[3] = { 1.0, 1.0, 1.0 };
  double BandWidth = 1.0;
  double Quantum = 1.0;
  /// Anatomy voxels within the band of a sample, along each axis.
  int Reach[3] = { 1, 1, 1 };
  double SurfaceSmoothing = 1.0;
  /// The in-slice Gaussian of SurfaceSmoothing.
  std::vector<double> SmoothingKernel;

  /**
   * The built bricks by brick ID: nullptr not built yet, FreeBrick() built
   * and free, else the brick's shield (owned). Sized by SetFieldGeometry.
   */
  std::unique_ptr<std::atomic<Brick*>[]> Directory;
  vtkIdType DirectorySize = 0;
  /// The directory's mark of a brick built and found free (never dereferenced).
  static Brick* FreeBrick();
  std::atomic<vtkIdType> BuiltBricks{ 0 };
  std::atomic<vtkIdType> ShieldBricks{ 0 };
  vtkIdType BricksBuiltOnDemand = 0;
  std::atomic<vtkIdType> PreparedBricks{ 0 };
  /// Serialises preparers, and ClearBricks with them (the writer's GetBrick never takes it).
  std::mutex PreparerMutex;

  /// BuildBrick's working memory, kept between bricks (one for the writer, one for the preparer).
  std::unique_ptr<Scratch> BuildScratch;
  std::unique_ptr<Scratch> PrepareScratch;

private:
  vtkVolumeCutProtection(const vtkVolumeCutProtection&) = delete;
  void operator=(const vtkVolumeCutProtection&) = delete;
};

#endif
