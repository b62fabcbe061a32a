// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkFalconKinematics
 * @brief   The Novint Falcon's delta-robot kinematics, as pure math.
 *
 * The Falcon is a delta robot: three legs 120 degrees apart, each a motor-
 * driven upper arm and a parallelogram shin, whose geometry R. E. Stamper
 * described (PhD thesis, University of Maryland, 1997) and libnifalcon
 * measured (include/falcon/core/FalconGeometry.h). In the frame of leg i
 * (the device frame turned by its angle phi_i about z, then offset by
 * (-r, -s, 0)), with upper-arm angle theta1, parallelogram angles theta2 and
 * theta3, and K = d + e + b sin(theta3), the end effector is at
 *
 *     u = a cos(theta1) - c + K cos(theta2)
 *     v = b cos(theta3) - f
 *     w = a sin(theta1) + K sin(theta2)
 *
 * Inverse kinematics solves these in closed form (theta3 from v, theta1 from
 * a quadratic in tan(theta1 / 2), theta2 from u); forward kinematics finds
 * the position whose inverse gives the measured motor angles by Newton-
 * Raphson on the Jacobian d(theta1)/d(position). A force F at the handle
 * needs the motor torques tau = J^-T F (virtual work: tau . d(theta) =
 * F . dx), scaled so that no motor command leaves the 16-bit range (the
 * direction of the force is kept) and rounded to integers.
 *
 * No I/O: encoders and commands in, positions and commands out. Positions
 * here are in millimetres with the origin at the centre of the workspace,
 * 135 mm in front of the legs' plane: the handle's position with all three
 * encoders at 0 (to within half a millimetre), about which the legs reach
 * a ball of 40 mm radius (CHAI3D's figure for the Falcon's workspace).
 * Forces are in newtons.
 *
 * @sa vtkNovintFalconDevice vtkFalconFrameCodec
 */

#ifndef vtkFalconKinematics_h
#define vtkFalconKinematics_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkFalconKinematics : public vtkObject
{
public:
  static vtkFalconKinematics* New();
  vtkTypeMacro(vtkFalconKinematics, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Motor angle (radians) of an encoder count: 320 slots read in quadrature
  /// on a 14.25 mm shaft driving a 110 mm arm drum, 35 degrees at count 0.
  static double EncoderToAngle(int encoder);

  /// The encoder count nearest to a motor angle (radians): EncoderToAngle's inverse.
  static int AngleToEncoder(double angle);

  /**
   * Upper-arm angles (radians) of the three legs for a handle position (mm,
   * workspace frame). Returns false, leaving angles unchanged, for a
   * position the legs cannot reach or that is not finite.
   */
  bool InverseKinematics(const double position[3], double angles[3]) const;

  /**
   * All three angles of leg 0..2 for a position: theta1 (upper arm), theta2
   * and theta3 (parallelogram). False where the leg cannot reach.
   */
  bool LegAngles(int leg, const double position[3], double theta[3]) const;

  /**
   * The handle position (mm) of leg leg's angles by the leg's forward
   * equations (see the class description): what InverseKinematics inverts.
   */
  void LegPosition(int leg, const double theta[3], double position[3]) const;

  /**
   * The handle position (mm) whose inverse kinematics gives these motor
   * angles: Newton-Raphson from guess (the workspace centre if nullptr).
   * Returns false, leaving position unchanged, if it does not converge to
   * within 1e-9 radians in 30 iterations or leaves the reachable space.
   */
  bool ForwardKinematics(const double angles[3], double position[3], const double guess[3] = nullptr) const;

  /// ForwardKinematics of three encoder counts.
  bool EncodersToPosition(const int encoders[3], double position[3], const double guess[3] = nullptr) const;

  /**
   * d(theta1)/d(position) (radians per mm) at a position, row i for leg i,
   * by central differences of the closed-form inverse. False where a leg
   * cannot reach.
   */
  bool ComputeJacobian(const double position[3], double jacobian[3][3]) const;

  /**
   * Motor torques (N m) that render the force (N) at the handle at this
   * position: tau = J^-T F. False where the Jacobian is singular or a leg
   * cannot reach (torques are then zero).
   */
  bool ForceToTorques(const double position[3], const double force[3], double torques[3]) const;

  /**
   * The motor commands for a force at a position: the torques times
   * MotorCommandsPerNewtonMetre, all scaled down together if one would leave
   * [-MaximumMotorCommand, MaximumMotorCommand], rounded. Returns false (and
   * zero commands) where ForceToTorques fails; saturated is set when they
   * had to be scaled.
   */
  bool ForceToMotorCommands(const double position[3], const double force[3], short commands[3], bool& saturated) const;

  ///@{
  /**
   * Set/get the motor command per N m of torque. libnifalcon drives the
   * motors with -10000 per N m; the sign turns the legs' positive angle into
   * the motors' direction. Default is -10000.
   */
  vtkSetMacro(MotorCommandsPerNewtonMetre, double);
  vtkGetMacro(MotorCommandsPerNewtonMetre, double);
  ///@}

  ///@{
  /**
   * Set/get the largest motor command sent (at most 32767, the frame's
   * 16-bit range). Default is 32767.
   */
  vtkSetClampMacro(MaximumMotorCommand, int, 0, 32767);
  vtkGetMacro(MaximumMotorCommand, int);
  ///@}

protected:
  vtkFalconKinematics() = default;
  ~vtkFalconKinematics() override = default;

  /// Position in metres in the kinematic frame (legs' plane at z = 0).
  void ToKinematicFrame(const double position[3], double metres[3]) const;

  double MotorCommandsPerNewtonMetre = -10000.0;
  int MaximumMotorCommand = 32767;

private:
  vtkFalconKinematics(const vtkFalconKinematics&) = delete;
  void operator=(const vtkFalconKinematics&) = delete;
};

#endif
