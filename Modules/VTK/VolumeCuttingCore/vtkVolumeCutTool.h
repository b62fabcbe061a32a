// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutTool
 * @brief   Shape of a cutting tool, as a signed distance in its own frame.
 *
 * A tool is a closed solid given in its local frame (mm): its signed distance
 * (negative inside) and the radius of a sphere about the local origin that
 * holds it. vtkVolumeCutField sweeps it between two poses. The spherical burr
 * has a faster path of its own (vtkVolumeCutField::CutCapsule); subclasses
 * give burrs of other shapes, blades, saws, or any closed mesh.
 *
 * @sa vtkVolumeCutCylinderTool vtkVolumeCutEllipsoidTool vtkVolumeCutBoxTool vtkVolumeCutMeshTool
 */

#ifndef vtkVolumeCutTool_h
#define vtkVolumeCutTool_h

#include "vtkObject.h"
#include "vtkWrappingHints.h" // For VTK_WRAPEXCLUDE
#include "vtkVolumeCuttingCoreExport.h" // For export macro

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutTool : public vtkObject
{
public:
  vtkTypeMacro(vtkVolumeCutTool, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Signed distance (mm) from a point in the tool's frame to its surface;
  /// negative inside. It must be exact near the surface (within the cut
  /// field's band) and may underestimate farther away.
  virtual double EvaluateDistance(const double local[3]) = 0;

  /// EvaluateDistance at count points given as coordinate runs (the cut
  /// field's writer evaluates whole bricks, in single precision). The default
  /// calls EvaluateDistance for each; shapes with a closed form override it
  /// with a loop that vectorises.
  VTK_WRAPEXCLUDE virtual void EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances);

  /// Radius (mm) of a sphere about the local origin that holds the tool.
  virtual double GetBoundingRadius() = 0;

  /// Half sizes (mm) of a box about the local origin, along the local axes,
  /// that holds the tool. The cut field's writer visits only the bricks near
  /// the box's copies, so a flat tool (a disk saw) need not pay for the cube
  /// around its bounding sphere. The default, the bounding radius on each
  /// axis, is always safe.
  virtual void GetLocalHalfExtents(double halfExtents[3]);

  /**
   * Whether the ball of the given radius about center (tool frame, mm) is
   * left behind when the tool translates by any positive multiple of motion
   * (tool frame): the tool's distance gets no smaller anywhere in the ball,
   * because the distance's gradient there has no component along motion. A
   * sweep continuing the previous one, which already cut the first pose,
   * need not compute such regions again. The default, false (not known), is
   * always safe; convex tools with a closed form answer from their geometry.
   */
  virtual bool IsLeftBehind(const double center[3], double radius, const double motion[3]);

  /**
   * Distances (as EvaluateDistances) to the volume the tool sweeps when it
   * translates by motion (tool frame, mm), for tools with a closed form for
   * it: exact, or within step of the exact sweep and no larger than the
   * distance to the union of copies step apart. Returns false, writing
   * nothing, for tools without one (the default): the sweep is then made of
   * copies. One evaluation instead of one per copy is what lets non-spherical
   * burrs keep up with a haptic loop.
   */
  VTK_WRAPEXCLUDE virtual bool EvaluateTranslatedDistances(
    const double motion[3], double step, const float* x, const float* y, const float* z, int count, float* distances);

  /**
   * Lower bounds (mm) of EvaluateTranslatedDistances (same motion and step)
   * over count parallel flat slices (tool frame): slice s holds the points
   * origin + s * stride + u * edges[0] + v * edges[1], u and v in [0, 1].
   * The cut field's writer evaluates only the slices of a brick (its
   * z-slices) whose bound is within its band, so a flat tool (a disk saw)
   * pays for the few it crosses, not for whole bricks. A tool bounding the
   * radial and axial terms of its distance separately gets far tighter
   * bounds than one sphere about the brick. Returns false, writing nothing,
   * when not known (the default): every slice is then evaluated.
   */
  VTK_WRAPEXCLUDE virtual bool BoundTranslatedDistances(const double motion[3], double step, const double origin[3], const double stride[3],
    const double edges[2][3], int count, double* bounds);

  /// Whether the tool can cut: finite, positive sizes (and a closed surface for
  /// meshes). Logs an error saying what is wrong otherwise.
  virtual bool IsValid() = 0;

protected:
  vtkVolumeCutTool() = default;
  ~vtkVolumeCutTool() override = default;

private:
  vtkVolumeCutTool(const vtkVolumeCutTool&) = delete;
  void operator=(const vtkVolumeCutTool&) = delete;
};

#endif
