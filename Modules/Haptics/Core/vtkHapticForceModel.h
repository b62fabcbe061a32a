// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticForceModel
 * @brief   Contact forces from the fields the renderer draws, through a proxy.
 *
 * What is felt is what is drawn (seed 000): the anatomy is solid where the
 * CT, trilinearly interpolated exactly as the ray caster does, is at or
 * above SurfaceIsoValue, and the cut field's signed distance
 * (vtkVolumeCutField::GetSignedDistance, the renderer's reconstruction) is
 * not negative. The tool is sampled by a point shell (vtkHapticPointShell,
 * 82 points by default, seed 003); every shell point inside solid material
 * traces toward the tool's centre to where the material ends (steps of half
 * the finest grid spacing, the first one guided by the cut field's distance,
 * then regula falsi on the CT or the cut field) and pushes the tool out along
 * that line with ContactStiffness times the depth.
 *
 * Proxy. Those penalty forces act on a proxy of the tool (god-object,
 * virtual coupling): each tick the proxy moves toward the device's pose
 * until the coupling spring (CouplingStiffness) balances the contact
 * forces, in at most ProxyIterations steps no longer than the shell's
 * spacing (so it cannot jump through thin bone). Each step follows the net
 * force as far as the stiffness in its direction says (the coupling's, and
 * each contact's share along it), and stops where the cut ahead of the
 * proxy ends, as the cut field's distances tell: while drilling, the proxy
 * comes to rest on the bone the last bite left in two to four contact
 * tests instead of stepping into it and backing out. The hand feels the
 * coupling spring plus damping of the hand's motion relative to the proxy,
 * both limited to what the device renders stably, however stiff the
 * contact is: high contact stiffness stays stable. The tool is drawn, and
 * cuts, at the proxy.
 *
 * Drilling. While the drill runs and the tool touches material, the cut is
 * made ahead of the proxy toward the hand by a bite of FeedRatePerNewton
 * times the hand's push (N) times the time step, at most MaximumFeedRate:
 * the burr advances into bone as fast as the user pushes, the material in
 * front goes, and the proxy follows next tick.
 *
 * Guided drilling (seed 001): an axis (from a markups line in the
 * integration) becomes a virtual fixture, a spring of GuideStiffness pulling
 * the hand back to the axis. Vibration (vtkHapticVibration) is added along
 * the tool's axis while the drill runs.
 *
 * Limits. SetDeviceLimits takes the device's capabilities and the scale of
 * its frame in the scene: coupling and guide stiffness, damping and the
 * total force (vibration included) never exceed what the device renders.
 *
 * Threads. Configure and Prepare on the main thread while no loop runs;
 * Update on the haptic thread. Update neither allocates nor locks; the cut
 * field is only read here.
 *
 * @sa vtkHapticLoop vtkHapticPointShell vtkVolumeCutField
 */

#ifndef vtkHapticForceModel_h
#define vtkHapticForceModel_h

#include "vtkNew.h" // For the shell and vibration
#include "vtkObject.h"
#include "vtkSmartPointer.h"               // For the inputs
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

class vtkBinaryVoxelCutter;
class vtkHapticDeviceCapabilities;
class vtkHapticPointShell;
class vtkHapticVibration;
class vtkImageData;
class vtkMatrix4x4;
class vtkVolumeCutField;
class vtkVolumeCutTool;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticForceModel : public vtkObject
{
public:
  static vtkHapticForceModel* New();
  vtkTypeMacro(vtkHapticForceModel, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The anatomy: CT intensities on their IJK grid (one component, any
   * scalar type; the image's origin and spacing are ignored) and the
   * IJK-to-RAS matrix that places them, as the renderer takes them.
   */
  void SetAnatomy(vtkImageData* intensities, vtkMatrix4x4* ijkToRAS);
  vtkImageData* GetAnatomy();

  ///@{
  /**
   * Set/get the CT value at and above which the anatomy is solid (the
   * renderer's surface iso-value). Default is 300.
   */
  vtkSetMacro(SurfaceIsoValue, double);
  vtkGetMacro(SurfaceIsoValue, double);
  ///@}

  /// The removed region; nullptr: nothing removed.
  void SetCutField(vtkVolumeCutField* field);
  vtkVolumeCutField* GetCutField();

  ///@{
  /**
   * The tool: a spherical burr of SphereRadius (mm) when no tool is set,
   * else any vtkVolumeCutTool (cylinder burr, disk saw, ...). Default radius 2.5.
   */
  vtkSetClampMacro(SphereRadius, double, 0.0, 1000.0);
  vtkGetMacro(SphereRadius, double);
  void SetTool(vtkVolumeCutTool* tool);
  vtkVolumeCutTool* GetTool();
  ///@}

  ///@{
  /**
   * Set/get the number of shell points (6 to 4096). Default is 82 (seed 003).
   */
  vtkSetClampMacro(NumberOfShellPoints, int, 6, 4096);
  vtkGetMacro(NumberOfShellPoints, int);
  ///@}

  /// The shell Prepare built.
  vtkHapticPointShell* GetPointShell();

  ///@{
  /**
   * Set/get the stiffness (N/mm) of the contact between a shell point and
   * the material it entered. It acts on the proxy only, so it may be far
   * stiffer than any device. Default is 20.
   */
  vtkSetClampMacro(ContactStiffness, double, 1e-6, 1.0e6);
  vtkGetMacro(ContactStiffness, double);
  ///@}

  ///@{
  /**
   * Set/get the stiffness (N/mm) of the coupling between the hand and the
   * proxy; the hand feels at most the device's limit. Default is 1.
   */
  vtkSetClampMacro(CouplingStiffness, double, 1e-6, 1.0e4);
  vtkGetMacro(CouplingStiffness, double);
  ///@}

  ///@{
  /**
   * Set/get the damping (N s/mm) of the hand's motion relative to the
   * proxy; at most the device's limit is applied. Default is 0.003.
   */
  vtkSetClampMacro(Damping, double, 0.0, 1.0e3);
  vtkGetMacro(Damping, double);
  ///@}

  ///@{
  /**
   * Set/get the most proxy steps per tick. Default is 6.
   */
  vtkSetClampMacro(ProxyIterations, int, 1, 64);
  vtkGetMacro(ProxyIterations, int);
  ///@}

  ///@{
  /**
   * Set/get the proxy step (mm) below which the proxy counts as settled
   * and the tick's remaining steps are skipped. Each step costs a full
   * contact test of the shell; a step this short changes the coupling
   * force by at most CouplingStiffness times it. Default is 0.001 mm.
   */
  vtkSetClampMacro(ProxyTolerance, double, 0.0, 1.0);
  vtkGetMacro(ProxyTolerance, double);
  ///@}

  ///@{
  /**
   * Set/get how fast the drill advances into material: mm/s per newton of
   * push, and at most. Defaults are 4 and 20.
   */
  vtkSetClampMacro(FeedRatePerNewton, double, 0.0, 1.0e4);
  vtkGetMacro(FeedRatePerNewton, double);
  vtkSetClampMacro(MaximumFeedRate, double, 0.0, 1.0e4);
  vtkGetMacro(MaximumFeedRate, double);
  ///@}

  /**
   * Limit stiffness, damping, force and vibration to a device's
   * capabilities; scale is the scene's millimetres per device millimetre
   * (a spring of k N per scene mm is k * scale N per device mm at the hand).
   * Without a call (or with nullptr) there is no force at all: a model for
   * an input-only device still keeps its proxy out of the material.
   */
  void SetDeviceLimits(vtkHapticDeviceCapabilities* capabilities, double scale);

  /// The largest force (N) and the stiffness (N/mm), damping (N s/mm) actually applied at the hand, after the device's limits.
  vtkGetMacro(MaximumForce, double);
  vtkGetMacro(AppliedCouplingStiffness, double);
  vtkGetMacro(AppliedDamping, double);
  vtkGetMacro(AppliedGuideStiffness, double);

  ///@{
  /**
   * Guided drilling: a virtual fixture pulling the hand back to the line
   * through point along direction (RAS). False (and an error) for a
   * direction of zero length or non-finite input, keeping the previous guide.
   */
  bool SetGuideAxis(const double point[3], const double direction[3]);
  void RemoveGuide();
  vtkGetMacro(GuideEnabled, bool);
  ///@}

  ///@{
  /**
   * Set/get the stiffness (N/mm) of the guide; the device's limit applies. Default is 1.
   */
  vtkSetClampMacro(GuideStiffness, double, 0.0, 1.0e4);
  vtkGetMacro(GuideStiffness, double);
  ///@}

  /// The drill's vibration (configure per burr type).
  vtkHapticVibration* GetVibration();

  ///@{
  /**
   * Set/get whether the running drill vibrates. Default is true.
   */
  vtkSetMacro(VibrationEnabled, bool);
  vtkGetMacro(VibrationEnabled, bool);
  vtkBooleanMacro(VibrationEnabled, bool);
  ///@}

  ///@{
  /**
   * Set/get the highest vibration frequency (Hz) the loop and device render:
   * the loop sets it to a quarter of the slower rate. Default is 250.
   */
  vtkSetClampMacro(MaximumVibrationFrequency, double, 0.0, 1.0e5);
  vtkGetMacro(MaximumVibrationFrequency, double);
  ///@}

  ///@{
  /**
   * Cuts made for the tool but not yet in the cut field: the haptic loop's
   * cutter thread cuts the segments the ticks queue a moment later (see
   * vtkHapticLoop::AsynchronousCutting). Update treats the spherical burr's
   * capsules from p0 to p1 (centres, RAS; SphereRadius) as removed already,
   * except in shielded anatomy voxels, which the cutter will keep: the
   * proxy then feels the bone as the tick that cut it left it, as if it had
   * cut it itself, not the bone the cutter has not reached yet. The capsule
   * is the burr's exact sweep; other tools' pending sweeps are not known here
   * (AddPendingCut refuses them, returning false). At most
   * MaximumPendingCuts; a further one is refused. Haptic thread, between
   * Updates; IsSolid and ComputeContactForce never count them.
   */
  static constexpr int MaximumPendingCuts = 64;
  void ClearPendingCuts();
  bool AddPendingCut(const double p0[3], const double p1[3]);
  int GetNumberOfPendingCuts() const;
  ///@}

  /**
   * Check the inputs and build the shell and lookups. False, with an error
   * naming what is missing or wrong, if the anatomy or tool cannot be used.
   */
  bool Prepare();

  /// Put the proxy at a position (RAS mm) and forget the motion: after Prepare, and when a device comes back.
  void Reset(const double position[3]);

#ifndef __VTK_WRAP__
  /// What one tick produced.
  struct Result
  {
    /// Force for the hand (N, RAS), limits applied, vibration included.
    double Force[3];
    /// The tool's centre where it is drawn (RAS mm).
    double ProxyPosition[3];
    /// Where the tool cuts this tick, when Cut.
    double CutPosition[3];
    bool Cut;
    /// Shell points in material, and the magnitude (N) of their push on the proxy.
    int NumberOfContacts;
    double ContactForce;
    /// Vibration added along the tool axis (N, signed).
    double Vibration;
    /// Contact tests the proxy took this tick (at most ProxyIterations).
    int NumberOfProxySteps;
    /// Points of the anatomy the tick's contact tests looked up (CT and
    /// cut field), traces included: what the tick's work grows with.
    int NumberOfSamples;
    /// Of those, the cut field's lookups (the costlier kind: curvature-corrected distances).
    int NumberOfCutFieldSamples;
    /// The deepest shell point's depth in material (mm) at the last contact test.
    double Immersion;
  };

  /**
   * One haptic tick: the device's tool pose (RAS mm, tool-to-RAS rotation),
   * the time since the last tick (s) and whether the drill runs.
   */
  void Update(const double position[3], const double rotation[3][3], double timeStep, bool drilling, Result& result);
#endif

  ///@{
  /**
   * Update for Python and tests: the tool's rotation is ToolRotation (the
   * 3x3 part of the matrix; identity by default); results are read back with
   * the getters below.
   */
  void SetToolRotation(vtkMatrix4x4* toolToRAS);
  void Step(const double position[3], double timeStep, bool drilling);
  void GetForce(double force[3]) const;
  void GetProxyPosition(double position[3]) const;
  void GetCutPosition(double position[3]) const;
  bool GetLastStepCut() const;
  int GetNumberOfContacts() const;
  /// Contact tests the proxy took in the last Update (each tests the whole shell).
  int GetNumberOfProxySteps() const;
  ///@}

  /**
   * The penalty force (N, RAS) that the shell's contacts exert on the tool
   * at a position (ToolRotation), without proxy or limits, and the number of
   * shell points in material. State is not changed.
   */
  int ComputeContactForce(const double position[3], double force[3]);

  /// Whether a RAS point is in solid material (the renderer's classification).
  bool IsSolid(const double ras[3]) const;

  /**
   * The baseline for benchmarks: how many shell points at a position are in
   * material by whole-voxel lookups, as voxel-based simulators test contact
   * (the nearest voxel's CT value, and its removal in a whole-voxel cutter).
   */
  int CountWholeVoxelContacts(const double position[3], vtkBinaryVoxelCutter* removed);

protected:
  vtkHapticForceModel();
  ~vtkHapticForceModel() override;

  /**
   * Penalty force of the shell at a pose; returns the number of contacts.
   * With record, keeps the contacts' push directions and the clearances of
   * the points in the cut for the proxy's step (Update only: the haptic thread's);
   * with work, adds the points it looked up and gives the deepest contact.
   */
  struct ContactWork
  {
    int Samples = 0;
    int CutFieldSamples = 0;
    double Deepest = 0.0;
  };
  int Contact(const double position[3], const double rotation[3][3], double force[3], bool record = false, ContactWork* work = nullptr) const;
  /// The proxy's step toward the hand against the last recorded contact test.
  void ProxyMove(const double proxy[3], const double hand[3], int contacts, const double contact[3], double move[3]) const;
  /// What makes a point solid: the CT above the iso-value and the cut
  /// field not removed there (the renderer's classification).
  struct Margins
  {
    double Anatomy;  ///< CT less the iso-value (solid when not negative)
    double Removal;  ///< the cut field's signed distance (mm; removed when negative), measured only where the CT is solid
    bool InBox;      ///< inside the CT's box
    bool CutLookedUp; ///< whether the cut field was looked up (the costlier lookup)
    bool IsSolid() const { return this->InBox && !(this->Anatomy < 0.0) && !(this->Removal < 0.0); }
  };
  /// withCut false leaves the cut field out (Removal stays the largest double);
  /// pending counts the pending cuts near the proxy (Update only).
  void Measure(const double ras[3], Margins& margins, bool withCut = true, bool pending = false) const;
  /// The cut field's signed distance at a RAS point, with pending the pending cuts near the proxy counted as removed.
  double RemovalDistance(const double ras[3], bool pending) const;
  /// Distance from p (in material, with its margins) along unit u to where the material ends, at most length;
  /// adds the points it looked up to samples.
  double ExitDistance(const double p[3], const double u[3], double length, const Margins& atStart, int& samples, int& cutSamples,
    bool pending) const;

  vtkSmartPointer<vtkImageData> Anatomy;
  vtkSmartPointer<vtkMatrix4x4> AnatomyIJKToRAS;
  vtkSmartPointer<vtkVolumeCutField> CutField;
  vtkSmartPointer<vtkVolumeCutTool> Tool;
  vtkNew<vtkHapticPointShell> PointShell;
  vtkNew<vtkHapticVibration> Vibration;
  double SurfaceIsoValue = 300.0;
  double SphereRadius = 2.5;
  int NumberOfShellPoints = 82;
  double ContactStiffness = 20.0;
  double CouplingStiffness = 1.0;
  double Damping = 0.003;
  int ProxyIterations = 6;
  double ProxyTolerance = 1e-3;
  double FeedRatePerNewton = 4.0;
  double MaximumFeedRate = 20.0;
  double GuideStiffness = 1.0;
  bool GuideEnabled = false;
  double GuidePoint[3] = { 0.0, 0.0, 0.0 };
  double GuideDirection[3] = { 0.0, 0.0, 1.0 };
  bool VibrationEnabled = true;
  double MaximumVibrationFrequency = 250.0;

  // Device limits (SetDeviceLimits) and what they leave.
  double DeviceMaximumForce = 0.0;
  double DeviceMaximumStiffness = 0.0;
  double DeviceMaximumDamping = 0.0;
  double DeviceScale = 1.0;
  double MaximumForce = 0.0;
  double AppliedCouplingStiffness = 0.0;
  double AppliedDamping = 0.0;
  double AppliedGuideStiffness = 0.0;

  double ToolRotation[3][3] = { { 1.0, 0.0, 0.0 }, { 0.0, 1.0, 0.0 }, { 0.0, 0.0, 1.0 } };

  struct Internals;
  Internals* Internal;

private:
  vtkHapticForceModel(const vtkHapticForceModel&) = delete;
  void operator=(const vtkHapticForceModel&) = delete;
};

#endif
