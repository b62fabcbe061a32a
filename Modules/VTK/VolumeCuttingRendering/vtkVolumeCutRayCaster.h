// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutRayCaster
 * @brief   CPU reference of adaptive multivolume ray casting (Pflesser et al.).
 *
 * Renders an anatomy (CT intensities, optionally a label map whose segments
 * have their own colour, opacity and surface definition) together with one or
 * more vtkVolumeCutField removed regions, without ever changing the anatomy.
 * Along each ray, samples are taken every SampleDistance voxels; between two
 * successive samples every border of every volume is located on its own
 * (bisection on the object classification, regula falsi on each cut field's
 * signed distance; clip planes and the volume's box analytically), the pieces
 * between borders are classified (inside a visible object, outside every cut,
 * not clipped) and the first visible piece is shaded with the normal of the
 * field whose border starts it: the CT's gray-level gradient on object
 * surfaces, the cut field's gradient on cut surfaces, the plane on clip
 * surfaces. Sharp edges where a cut meets an object are therefore exact to
 * the bisection tolerance, however far the view zooms in.
 *
 * The same algorithm runs on the GPU in vtkVolumeCutVolumeMapper; this class
 * is the reference it is tested against, the fallback where OpenGL cannot run
 * it, and the localized re-renderer of seed 004: when only cut fields changed
 * since the last call (same camera, same anatomy), only the rays whose pixels
 * cover a modified brick are recast.
 *
 * Coordinates: the anatomy's IJK-to-world matrix places the CT; cut fields are
 * in world coordinates (Slicer's RAS) and must have been initialised on the
 * anatomy's grid (a field on another grid is ignored with an error). Images
 * are width x height, row 0 at the bottom (OpenGL's convention).
 *
 * @sa vtkVolumeCutVolumeMapper vtkVolumeCutField
 */

#ifndef vtkVolumeCutRayCaster_h
#define vtkVolumeCutRayCaster_h

#include "vtkObject.h"
#include "vtkVolumeCuttingRenderingExport.h" // For export macro

#include <array>  // For SceneView
#include <memory> // For std::unique_ptr
#include <utility> // For SceneView
#include <vector> // For SceneView

class vtkColorTransferFunction;
class vtkImageData;
class vtkMatrix4x4;
class vtkPiecewiseFunction;
class vtkPlaneCollection;
class vtkVolumeCutField;

class VTK_VOLUMECUTTINGRENDERING_EXPORT vtkVolumeCutRayCaster : public vtkObject
{
public:
  static vtkVolumeCutRayCaster* New();
  vtkTypeMacro(vtkVolumeCutRayCaster, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// How samples become an image.
  enum BlendModes
  {
    /// First visible surface of each ray: object surfaces per segment, cut
    /// and clip surfaces, shaded (the main mode).
    IsoSurfaceBlend = 0,
    /// Direct volume rendering: front-to-back compositing of the transfer
    /// functions, with removed and clipped pieces of each step left out
    /// exactly and cut surfaces shaded with the cut field's normal.
    CompositeBlend = 1
  };

  ///@{
  /**
   * The anatomy: scalar CT (first component of any scalar type) and where
   * its voxels are (IJK to world; nullptr uses the image's own origin,
   * spacing and direction). The image is copied to floats when it changes.
   */
  void SetAnatomy(vtkImageData* intensities, vtkMatrix4x4* ijkToWorld);
  vtkImageData* GetAnatomy();
  ///@}

  /**
   * Optional label map on the anatomy's grid (integer labels 0..65535, 0 for
   * no segment). Without it (and without fractional labelmaps), every voxel
   * belongs to segment 1. A voxel grid
   * that differs from the anatomy's is refused with an error.
   */
  void SetLabelMap(vtkImageData* labels);

  ///@{
  /**
   * A fractional labelmap for the segment with the given label: an image on
   * the anatomy's grid whose first component maps linearly from valueAtZero
   * (voxel outside) to valueAtOne (voxel inside), e.g. 0..1 for floats or
   * -108..108 for Slicer's fractional labelmaps. Where the segment has one,
   * its interpolated fraction replaces the label map's binary indicator, so
   * its surface (shape mode) and its borders with other segments are placed
   * at sub-voxel accuracy. nullptr removes it; at most 16 segments.
   */
  void SetSegmentFraction(int label, vtkImageData* fraction, double valueAtZero = 0.0, double valueAtOne = 1.0);
  int GetNumberOfSegmentFractions() const;
  ///@}

  ///@{
  /**
   * Appearance of the segment with the given label: colour (0..1), opacity
   * (0 hides it; below 1 is translucent in iso-surface mode) and the surface:
   * the CT iso-value inside the segment, or NaN to take the segment's own
   * shape (its label indicator at 0.5). Labels without an appearance are
   * hidden. Segment 1 is white bone at IsoValue until set.
   */
  void SetSegmentAppearance(int label, const double color[3], double opacity, double isoValue);
  void RemoveAllSegmentAppearances();
  ///@}

  /**
   * Colour of the segment's own surface where it is not cut (its appearance's
   * colour until set; SetSegmentAppearance resets it). Cut and clip surfaces
   * keep the appearance's colour: segments of one material (cortical and
   * trabecular bone) look like one bone outside, and a cut shows which of
   * them it exposes. The segment needs an appearance first (else an error).
   */
  void SetSegmentSurfaceColor(int label, const double color[3]);
  ///@{
  int GetNumberOfSegmentAppearances() const;
  ///@}

  ///@{
  /** Cut fields whose removed regions are subtracted from the anatomy. */
  void AddCutField(vtkVolumeCutField* field);
  void RemoveAllCutFields();
  int GetNumberOfCutFields() const;
  ///@}

  /**
   * Clip planes (world): material on the side a plane's normal points to is
   * kept, as for vtkAbstractMapper's clipping planes. nullptr for none.
   */
  void SetClippingPlanes(vtkPlaneCollection* planes);

  ///@{
  /** Transfer functions of the composite mode (CT value to colour, opacity). */
  void SetTransferFunctions(vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity);
  vtkSetClampMacro(ScalarOpacityUnitDistance, double, 1e-6, 1e6);
  vtkGetMacro(ScalarOpacityUnitDistance, double);
  ///@}

  vtkSetClampMacro(BlendMode, int, IsoSurfaceBlend, CompositeBlend);
  vtkGetMacro(BlendMode, int);

  /// CT iso-value of segment 1 while no label map or appearance is given.
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);

  /// Distance between samples along a ray, in voxels of the anatomy.
  vtkSetClampMacro(SampleDistance, double, 0.05, 4.0);
  vtkGetMacro(SampleDistance, double);

  /// Step (voxels) of the central differences of the CT's gradient.
  vtkSetClampMacro(GradientStep, double, 0.01, 2.0);
  vtkGetMacro(GradientStep, double);

  ///@{
  /**
   * Thin-bone shading (Morris et al.): where an object is thinner than
   * ThinBoneThickness (mm) along the inward normal, it is shown red and
   * translucent, and what lies behind shows through.
   */
  vtkSetMacro(ThinBoneShading, bool);
  vtkGetMacro(ThinBoneShading, bool);
  vtkBooleanMacro(ThinBoneShading, bool);
  vtkSetClampMacro(ThinBoneThickness, double, 0.01, 100.0);
  vtkGetMacro(ThinBoneThickness, double);
  ///@}

  ///@{
  /**
   * Smoothing of segments drawn by their own shape from the label map
   * alone (no fractional labelmap), as Slicer smooths the closed surfaces it
   * makes of binary labelmaps: above 0, such a segment is drawn from a
   * fraction made by shape-based interpolation between slices (each slice's
   * signed distance to its outline, smoothed in the slice by a Gaussian of
   * this standard deviation in voxels), without the voxels' stairs and the
   * slices' terraces. Such segments count against the 16 fractional
   * labelmaps (4 on the GPU). 0 (the default) draws the label map's
   * trilinear indicator.
   */
  vtkSetClampMacro(LabelSmoothing, double, 0.0, 8.0);
  vtkGetMacro(LabelSmoothing, double);
  ///@}

  /**
   * How many smoothed fractions (one per segment drawn by its shape) were
   * computed since this caster was made. A segment's smoothed fraction
   * depends only on its own voxels and the smoothing, so changing another
   * segment's appearance (a role change in the application) computes none
   * again, and drawing one more segment by its shape computes one.
   */
  vtkTypeInt64 GetNumberOfLabelSmoothings() const;

  ///@{
  /**
   * Ambient occlusion, a depth cue that makes cavities read in a still
   * image: each surface point is darkened by how much of 14 points around
   * it, up to AmbientOcclusionRadius (mm) away over its normal's
   * hemisphere, lies in visible material (cuts removed), each point weighed
   * by its depth in the material so that the term varies smoothly over a
   * surface (vtkVolumeCutAmbientOcclusion). With it, cut surfaces are
   * darkened by the length of original material between them and the eye,
   * up to half the radius (vtkVolumeCutCavityShading), so that a drilled
   * pit seen head-on reads as a cavity, not as a bump. Off by default;
   * radius 6 mm.
   */
  vtkSetMacro(AmbientOcclusion, bool);
  vtkGetMacro(AmbientOcclusion, bool);
  vtkBooleanMacro(AmbientOcclusion, bool);
  vtkSetClampMacro(AmbientOcclusionRadius, double, 0.1, 100.0);
  vtkGetMacro(AmbientOcclusionRadius, double);
  ///@}

  ///@{
  /**
   * Set/get whether renders leave ambient occlusion out although it is on:
   * the mapper's frames drawn while the view moves. Unlike
   * SetAmbientOcclusion it does not modify the caster, so that the
   * empty-space structure is kept; the next render after a change recasts
   * the whole image. Default is false.
   */
  void SetDraftQuality(bool draft) { this->DraftQuality = draft; }
  bool GetDraftQuality() const { return this->DraftQuality; }
  ///@}

  ///@{
  /** Phong lighting with a headlight. */
  vtkSetMacro(Ambient, double);
  vtkGetMacro(Ambient, double);
  vtkSetMacro(Diffuse, double);
  vtkGetMacro(Diffuse, double);
  vtkSetMacro(Specular, double);
  vtkGetMacro(Specular, double);
  vtkSetMacro(SpecularPower, double);
  vtkGetMacro(SpecularPower, double);
  ///@}

  ///@{
  /**
   * At most this many threads cast rays (0, the default: one per core; 1:
   * the calling thread only, as a ThreadSanitizer run of the caller needs).
   */
  vtkSetClampMacro(MaximumNumberOfThreads, int, 0, 4096);
  vtkGetMacro(MaximumNumberOfThreads, int);
  ///@}

  /**
   * Cast the rays of a width x height image seen through \a worldToNDC (the
   * camera's composite projection: world to normalized device coordinates,
   * OpenGL convention, perspective or parallel). \a opaqueDepth, if given,
   * holds the window depth (0..1, width x height floats) of opaque geometry
   * already drawn: rays stop there. When only cut fields changed since the
   * previous call with the same camera and size, only pixels covering
   * modified bricks are recast (see GetNumberOfRaysCast). Returns false (and
   * an error) when there is nothing to render or the input is unusable.
   */
  bool Render(vtkMatrix4x4* worldToNDC, int width, int height, const float* opaqueDepth = nullptr);

  /// Forget the previous image: the next Render casts every ray.
  void InvalidateImage();

  ///@{
  /**
   * Results of the last Render (width x height, row 0 at the bottom):
   * premultiplied RGBA (4 floats a pixel), window depth of the first visible
   * surface (1 where none), its world normal (3 floats, 0 where none),
   * which border it is (SourceNone, SourceObject, SourceVolumeBox,
   * SourceClipPlane or SourceCutField + the cut field's index) and which
   * segment's material it shows (its label; 0 where none and in composite mode).
   */
  const float* GetColorBuffer() const;
  const float* GetDepthBuffer() const;
  const float* GetNormalBuffer() const;
  const int* GetSourceBuffer() const;
  const int* GetSegmentBuffer() const;
  void GetColorImage(vtkImageData* image) const;
  void GetDepthImage(vtkImageData* image) const;
  void GetNormalImage(vtkImageData* image) const;
  void GetSourceImage(vtkImageData* image) const;
  void GetSegmentImage(vtkImageData* image) const;
  ///@}

  enum SurfaceSources
  {
    SourceNone = 0,
    SourceObject = 1,
    SourceVolumeBox = 2,
    SourceClipPlane = 3,
    SourceCutField = 10
  };

  /// Rays cast by the last Render (all pixels, or those of a localized update).
  vtkGetMacro(NumberOfRaysCast, vtkIdType);

  /// Whether the last Render was a localized update.
  vtkGetMacro(LastRenderWasLocalized, bool);

  /**
   * Wall-clock seconds the last Render spent casting its rays (the rest of
   * it prepares the scene and the image): what a frame's cost grows with
   * the number of rays by.
   */
  vtkGetMacro(LastRayCastingTime, double);

  /// Pixel rectangle (x0, y0, x1, y1, inclusive) the last Render changed;
  /// empty (x1 < x0) when it cast no ray.
  vtkGetVector4Macro(UpdatedRegion, int);

  struct Internals;

#ifndef __VTK_WRAP__
  /**
   * The prepared scene as plain data, for the OpenGL implementation of the
   * same algorithm (vtkVolumeCutOpenGLRayCaster): valid until the next call
   * that changes this object. Version changes whenever anything but the cut
   * fields' contents changed.
   */
  struct SceneView
  {
    vtkMTimeType Version = 0;
    vtkMTimeType AnatomyVersion = 0; // changes when the CT values or grid change
    vtkMTimeType LabelVersion = 0;   // changes when the label map or fractions change
    const float* Values = nullptr;
    int Dimensions[3] = { 0, 0, 0 };
    double IJKToWorld[16];
    double WorldToIJK[16];
    double NormalMatrix[16];
    const unsigned short* Labels = nullptr;
    /// Fractional labelmaps: (label, fractions 0..1 on the anatomy's grid).
    std::vector<std::pair<int, const float*>> Fractions;
    /// Per label: r, g, b, opacity, iso-value, shape flag, 0, 0, and the
    /// uncut surface's r, g, b, 0.
    std::vector<std::array<float, 12>> Styles;
    int BlockDimensions[3] = { 0, 0, 0 };
    const unsigned char* BlockOccupied = nullptr;
    const float* BlockLipschitz = nullptr;
    /// Per block, the chessboard distance in blocks to the nearest occupied one (0: occupied; at most 255).
    const unsigned char* BlockReach = nullptr;
    /// Iso-surface mode: per 2 x 2 x 2 cells, a byte whose bit
    /// (i & 1) | (j & 1) << 1 | (k & 1) << 2 says whether cell (i, j, k) may
    /// hold a visible object; nullptr (and 0 groups) when cells are not classified.
    int CellGroupDimensions[3] = { 0, 0, 0 };
    const unsigned char* CellGroups = nullptr;
    bool AnyIsoSegment = false;
    double MinimumIso = 0.0;
    std::vector<vtkVolumeCutField*> CutFields;
    std::vector<std::array<double, 4>> Planes;
    const float* ColorTable = nullptr;
    const float* OpacityTable = nullptr;
    int TableSize = 0;
    double TableRange[2] = { 0.0, 1.0 };
    int MaximumRefinements = 0;
  };
  bool UpdateScene(SceneView& view);
#endif

protected:
  vtkVolumeCutRayCaster();
  ~vtkVolumeCutRayCaster() override;

  int BlendMode = IsoSurfaceBlend;
  double IsoValue = 300.0;
  double SampleDistance = 0.5;
  double GradientStep = 1.0;
  double ScalarOpacityUnitDistance = 1.0;
  bool ThinBoneShading = false;
  double ThinBoneThickness = 1.0;
  double Ambient = 0.15;
  double Diffuse = 0.7;
  double Specular = 0.15;
  double SpecularPower = 30.0;
  double LabelSmoothing = 0.0;
  bool AmbientOcclusion = false;
  double AmbientOcclusionRadius = 6.0;
  bool DraftQuality = false;
  int MaximumNumberOfThreads = 0;
  vtkIdType NumberOfRaysCast = 0;
  bool LastRenderWasLocalized = false;
  double LastRayCastingTime = 0.0;
  int UpdatedRegion[4] = { 0, 0, -1, -1 };

  bool PrepareScene(bool& sceneChanged);

private:
  vtkVolumeCutRayCaster(const vtkVolumeCutRayCaster&) = delete;
  void operator=(const vtkVolumeCutRayCaster&) = delete;

  std::unique_ptr<Internals> Impl;
};

#endif
