// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkFalconKinematics.h"

#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkFalconKinematics);

namespace
{
// The Falcon's geometry in metres (libnifalcon's FalconGeometry.h, after
// Stamper's diagram): upper arm a, parallelogram side b, effector offsets c
// and f, joint lengths d and e, leg base offsets r and s.
constexpr double A = 0.060;
constexpr double B = 0.1025;
constexpr double C = 0.01443;
constexpr double D = 0.01125;
constexpr double E = D;
constexpr double F = -0.025;
constexpr double R = 0.0400;
constexpr double S = -0.02309;
constexpr double Pi = 3.14159265358979323846;
// Legs 120 degrees apart, each tilted 15 degrees from the desk plane.
constexpr double LegTilt = Pi / 12.0;
const double LegAngle[3] = { Pi / 2.0 + LegTilt, -Pi / 6.0 + LegTilt, -5.0 * Pi / 6.0 + LegTilt };
// Workspace centre in the kinematic frame (m): where the handle is with the
// arms at their reference angle (all encoders 0), to within half a
// millimetre; the 40 mm ball about it is reachable by every leg.
constexpr double WorkspaceDepth = 0.135;
// Encoder: 320 slots read in quadrature on a 14.25 mm shaft driving a 110 mm drum; 35 degrees at count 0.
constexpr double DegreesPerCount = (0.01425 * 360.0) / (320.0 * 4.0 * 0.110);
constexpr double AngleAtZero = 35.0;
} // namespace

//------------------------------------------------------------------------------
double vtkFalconKinematics::EncoderToAngle(int encoder)
{
  return vtkMath::RadiansFromDegrees(encoder * DegreesPerCount + AngleAtZero);
}

//------------------------------------------------------------------------------
int vtkFalconKinematics::AngleToEncoder(double angle)
{
  return static_cast<int>(std::lround((vtkMath::DegreesFromRadians(angle) - AngleAtZero) / DegreesPerCount));
}

//------------------------------------------------------------------------------
void vtkFalconKinematics::ToKinematicFrame(const double position[3], double metres[3]) const
{
  metres[0] = 0.001 * position[0];
  metres[1] = 0.001 * position[1];
  metres[2] = 0.001 * position[2] + WorkspaceDepth;
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::LegAngles(int leg, const double position[3], double theta[3]) const
{
  if (leg < 0 || leg > 2 || !std::isfinite(position[0]) || !std::isfinite(position[1]) || !std::isfinite(position[2]))
  {
    return false;
  }
  double x[3];
  this->ToKinematicFrame(position, x);
  const double cosine = std::cos(LegAngle[leg]);
  const double sine = std::sin(LegAngle[leg]);
  const double u = cosine * x[0] + sine * x[1] - R;
  const double v = -sine * x[0] + cosine * x[1] - S;
  const double w = x[2];
  const double cos3 = (v + F) / B;
  if (!(std::abs(cos3) <= 1.0))
  {
    return false;
  }
  const double theta3 = std::acos(cos3);
  const double k = D + E + B * std::sin(theta3);
  // (u + c - a cos t1)^2 + (w - a sin t1)^2 = k^2 as a quadratic in tan(t1 / 2).
  const double common = w * w + u * u + 2.0 * C * u + A * A + C * C - k * k;
  const double l0 = common - 2.0 * A * u - 2.0 * A * C;
  const double l1 = -4.0 * A * w;
  const double l2 = common + 2.0 * A * u + 2.0 * A * C;
  const double discriminant = l1 * l1 - 4.0 * l0 * l2;
  if (!(discriminant >= 0.0) || l2 == 0.0)
  {
    return false;
  }
  // The root of the knee-out configuration the Falcon is built in.
  const double t = (-l1 - std::sqrt(discriminant)) / (2.0 * l2);
  const double theta1 = 2.0 * std::atan(t);
  const double cos2 = (u - A * std::cos(theta1) + C) / k;
  const double sin2 = (w - A * std::sin(theta1)) / k;
  theta[0] = theta1;
  theta[1] = std::atan2(sin2, cos2);
  theta[2] = theta3;
  return std::isfinite(theta[0]) && std::isfinite(theta[1]);
}

//------------------------------------------------------------------------------
void vtkFalconKinematics::LegPosition(int leg, const double theta[3], double position[3]) const
{
  const double k = D + E + B * std::sin(theta[2]);
  const double u = A * std::cos(theta[0]) - C + k * std::cos(theta[1]);
  const double v = B * std::cos(theta[2]) - F;
  const double w = A * std::sin(theta[0]) + k * std::sin(theta[1]);
  const double cosine = std::cos(LegAngle[leg < 0 || leg > 2 ? 0 : leg]);
  const double sine = std::sin(LegAngle[leg < 0 || leg > 2 ? 0 : leg]);
  // Undo the leg frame's offset and turn.
  const double lu = u + R;
  const double lv = v + S;
  position[0] = 1000.0 * (cosine * lu - sine * lv);
  position[1] = 1000.0 * (sine * lu + cosine * lv);
  position[2] = 1000.0 * (w - WorkspaceDepth);
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::InverseKinematics(const double position[3], double angles[3]) const
{
  double result[3];
  for (int leg = 0; leg < 3; ++leg)
  {
    double theta[3];
    if (!this->LegAngles(leg, position, theta))
    {
      return false;
    }
    result[leg] = theta[0];
  }
  std::copy(result, result + 3, angles);
  return true;
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::ComputeJacobian(const double position[3], double jacobian[3][3]) const
{
  // Central differences of the closed form: 1 um steps keep both truncation
  // and rounding errors near 1e-9 of the derivative.
  const double step = 1e-3;
  for (int axis = 0; axis < 3; ++axis)
  {
    double plus[3] = { position[0], position[1], position[2] };
    double minus[3] = { position[0], position[1], position[2] };
    plus[axis] += step;
    minus[axis] -= step;
    double anglesPlus[3];
    double anglesMinus[3];
    if (!this->InverseKinematics(plus, anglesPlus) || !this->InverseKinematics(minus, anglesMinus))
    {
      return false;
    }
    for (int leg = 0; leg < 3; ++leg)
    {
      jacobian[leg][axis] = (anglesPlus[leg] - anglesMinus[leg]) / (2.0 * step);
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::ForwardKinematics(const double angles[3], double position[3], const double guess[3]) const
{
  if (!std::isfinite(angles[0]) || !std::isfinite(angles[1]) || !std::isfinite(angles[2]))
  {
    return false;
  }
  double x[3] = { 0.0, 0.0, 0.0 };
  if (guess && std::isfinite(guess[0]) && std::isfinite(guess[1]) && std::isfinite(guess[2]))
  {
    std::copy(guess, guess + 3, x);
  }
  double current[3];
  if (!this->InverseKinematics(x, current))
  {
    // A guess outside the reachable space: start from the centre instead.
    x[0] = x[1] = x[2] = 0.0;
    if (!this->InverseKinematics(x, current))
    {
      return false;
    }
  }
  double error = 0.0;
  for (int leg = 0; leg < 3; ++leg)
  {
    error = std::max(error, std::abs(angles[leg] - current[leg]));
  }
  for (int iteration = 0; iteration < 30 && error > 1e-9; ++iteration)
  {
    double jacobian[3][3];
    if (!this->ComputeJacobian(x, jacobian))
    {
      return false;
    }
    double delta[3] = { angles[0] - current[0], angles[1] - current[1], angles[2] - current[2] };
    double inverse[3][3];
    if (std::abs(vtkMath::Determinant3x3(jacobian)) < 1e-18)
    {
      return false;
    }
    vtkMath::Invert3x3(jacobian, inverse);
    double step[3];
    vtkMath::Multiply3x3(inverse, delta, step);
    // Halve the step until the error falls (the closed form is undefined
    // outside the reachable space, and far guesses overshoot).
    double scale = 1.0;
    bool improved = false;
    for (int attempt = 0; attempt < 20 && !improved; ++attempt, scale *= 0.5)
    {
      const double candidate[3] = { x[0] + scale * step[0], x[1] + scale * step[1], x[2] + scale * step[2] };
      double candidateAngles[3];
      if (!this->InverseKinematics(candidate, candidateAngles))
      {
        continue;
      }
      double candidateError = 0.0;
      for (int leg = 0; leg < 3; ++leg)
      {
        candidateError = std::max(candidateError, std::abs(angles[leg] - candidateAngles[leg]));
      }
      if (candidateError < error)
      {
        std::copy(candidate, candidate + 3, x);
        std::copy(candidateAngles, candidateAngles + 3, current);
        error = candidateError;
        improved = true;
      }
    }
    if (!improved)
    {
      break;
    }
  }
  if (!(error <= 1e-9))
  {
    return false;
  }
  std::copy(x, x + 3, position);
  return true;
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::EncodersToPosition(const int encoders[3], double position[3], const double guess[3]) const
{
  const double angles[3] = { EncoderToAngle(encoders[0]), EncoderToAngle(encoders[1]), EncoderToAngle(encoders[2]) };
  return this->ForwardKinematics(angles, position, guess);
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::ForceToTorques(const double position[3], const double force[3], double torques[3]) const
{
  torques[0] = torques[1] = torques[2] = 0.0;
  double jacobian[3][3];
  if (!std::isfinite(force[0]) || !std::isfinite(force[1]) || !std::isfinite(force[2]) || !this->ComputeJacobian(position, jacobian))
  {
    return false;
  }
  if (std::abs(vtkMath::Determinant3x3(jacobian)) < 1e-18)
  {
    return false;
  }
  // tau . dtheta = F . dx with dtheta = J dx: tau = J^-T F. The Jacobian is
  // per mm, the torques per metre of the force's travel.
  double inverse[3][3];
  vtkMath::Invert3x3(jacobian, inverse);
  for (int leg = 0; leg < 3; ++leg)
  {
    torques[leg] = 0.001 * (inverse[0][leg] * force[0] + inverse[1][leg] * force[1] + inverse[2][leg] * force[2]);
  }
  return std::isfinite(torques[0]) && std::isfinite(torques[1]) && std::isfinite(torques[2]);
}

//------------------------------------------------------------------------------
bool vtkFalconKinematics::ForceToMotorCommands(const double position[3], const double force[3], short commands[3], bool& saturated) const
{
  commands[0] = commands[1] = commands[2] = 0;
  saturated = false;
  double torques[3];
  if (!this->ForceToTorques(position, force, torques))
  {
    return false;
  }
  double raw[3];
  double largest = 0.0;
  for (int leg = 0; leg < 3; ++leg)
  {
    raw[leg] = torques[leg] * this->MotorCommandsPerNewtonMetre;
    largest = std::max(largest, std::abs(raw[leg]));
  }
  // Scale all three together: clamping one alone would turn the force.
  const double limit = this->MaximumMotorCommand;
  const double scale = largest > limit ? limit / largest : 1.0;
  saturated = scale < 1.0;
  for (int leg = 0; leg < 3; ++leg)
  {
    const double value = std::max(-limit, std::min(limit, std::round(raw[leg] * scale)));
    commands[leg] = static_cast<short>(value);
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkFalconKinematics::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "MotorCommandsPerNewtonMetre: " << this->MotorCommandsPerNewtonMetre << "\n";
  os << indent << "MaximumMotorCommand: " << this->MaximumMotorCommand << "\n";
}
