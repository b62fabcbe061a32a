// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The Falcon's delta kinematics as pure functions: the closed-form inverse
// against the legs' forward equations, forward kinematics (Newton-Raphson)
// against the inverse over the whole workspace, known poses from the
// geometry's symmetry, encoders, and the force mapping against virtual work
// and the 16-bit limit.
#include "vtkFalconKinematics.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMath.h>
#include <vtkNew.h>

#include <cmath>
#include <iostream>

int vtkFalconKinematicsTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkFalconKinematics> kinematics;

  // Known pose: on the axis of symmetry the three legs are alike, so their
  // angles agree, and forward kinematics of three equal angles stays on it.
  const double centre[3] = { 0.0, 0.0, 0.0 };
  double angles[3];
  CHECK_BOOL(kinematics->InverseKinematics(centre, angles), true);
  CHECK_DOUBLE_TOLERANCE(angles[1], angles[0], 1e-12);
  CHECK_DOUBLE_TOLERANCE(angles[2], angles[0], 1e-12);
  // The arms hang within their travel (encoder counts of a few thousand around 35 degrees).
  CHECK_BOOL(std::abs(vtkFalconKinematics::AngleToEncoder(angles[0])) < 3000, true);
  const int equalEncoders[3] = { 0, 0, 0 };
  double onAxis[3];
  CHECK_BOOL(kinematics->EncodersToPosition(equalEncoders, onAxis), true);
  CHECK_DOUBLE_TOLERANCE(onAxis[0], 0.0, 1e-6);
  CHECK_DOUBLE_TOLERANCE(onAxis[1], 0.0, 1e-6);
  // The workspace centre is the handle's reference pose, to half a millimetre.
  CHECK_DOUBLE_TOLERANCE(onAxis[2], 0.0, 0.5);
  std::cout << "encoders (0, 0, 0): handle at z = " << onAxis[2] << " mm from the workspace centre" << std::endl;

  // Encoders: 35 degrees at count 0, 0.0364 degree a count, and back.
  CHECK_DOUBLE_TOLERANCE(vtkFalconKinematics::EncoderToAngle(0), vtkMath::RadiansFromDegrees(35.0), 1e-12);
  CHECK_DOUBLE_TOLERANCE(
    vtkFalconKinematics::EncoderToAngle(1000) - vtkFalconKinematics::EncoderToAngle(0), vtkMath::RadiansFromDegrees(1000 * 5.13 / 140.8), 1e-9);
  for (int count = -20000; count <= 20000; count += 37)
  {
    if (vtkFalconKinematics::AngleToEncoder(vtkFalconKinematics::EncoderToAngle(count)) != count)
    {
      std::cerr << "encoder round trip failed at " << count << std::endl;
      return EXIT_FAILURE;
    }
  }

  // Over the workspace (a ball of 40 mm radius): the inverse satisfies every
  // leg's forward equations, and forward kinematics returns the position.
  double worstLeg = 0.0;
  double worstRoundTrip = 0.0;
  int poses = 0;
  for (double x = -40.0; x <= 40.0; x += 8.0)
  {
    for (double y = -40.0; y <= 40.0; y += 8.0)
    {
      for (double z = -40.0; z <= 40.0; z += 8.0)
      {
        if (x * x + y * y + z * z > 40.0 * 40.0)
        {
          continue;
        }
        const double position[3] = { x, y, z };
        if (!kinematics->InverseKinematics(position, angles))
        {
          std::cerr << "inverse kinematics failed inside the workspace at " << x << " " << y << " " << z << std::endl;
          return EXIT_FAILURE;
        }
        for (int leg = 0; leg < 3; ++leg)
        {
          double theta[3];
          double back[3];
          CHECK_BOOL(kinematics->LegAngles(leg, position, theta), true);
          CHECK_DOUBLE_TOLERANCE(theta[0], angles[leg], 0.0);
          kinematics->LegPosition(leg, theta, back);
          worstLeg = std::max(worstLeg, std::sqrt(vtkMath::Distance2BetweenPoints(back, position)));
        }
        double found[3];
        // From the workspace centre, as after the device is opened.
        if (!kinematics->ForwardKinematics(angles, found))
        {
          std::cerr << "forward kinematics did not converge for " << x << " " << y << " " << z << std::endl;
          return EXIT_FAILURE;
        }
        worstRoundTrip = std::max(worstRoundTrip, std::sqrt(vtkMath::Distance2BetweenPoints(found, position)));
        ++poses;
      }
    }
  }
  std::cout << poses << " poses: legs' equations within " << worstLeg << " mm, forward(inverse) within " << worstRoundTrip << " mm"
            << std::endl;
  CHECK_BOOL(worstLeg < 1e-9, true);
  CHECK_BOOL(worstRoundTrip < 1e-6, true);

  // Out of reach, or not a number: refused, output untouched.
  const double far[3] = { 0.0, 0.0, 400.0 };
  angles[0] = 123.0;
  CHECK_BOOL(kinematics->InverseKinematics(far, angles), false);
  CHECK_DOUBLE(angles[0], 123.0);
  const double nan[3] = { std::nan(""), 0.0, 0.0 };
  CHECK_BOOL(kinematics->InverseKinematics(nan, angles), false);
  const double nanAngles[3] = { std::nan(""), 0.5, 0.5 };
  double position[3] = { 9.0, 9.0, 9.0 };
  CHECK_BOOL(kinematics->ForwardKinematics(nanAngles, position), false);
  CHECK_DOUBLE(position[0], 9.0);

  // Force mapping: tau . dtheta equals F . dx for a small displacement (virtual work).
  const double at[3] = { 12.0, -7.0, 15.0 };
  const double force[3] = { 1.5, -2.0, 3.0 };
  double torques[3];
  CHECK_BOOL(kinematics->ForceToTorques(at, force, torques), true);
  const double step[3] = { 1e-4, -2e-4, 1.5e-4 }; // mm
  const double moved[3] = { at[0] + step[0], at[1] + step[1], at[2] + step[2] };
  double before[3];
  double after[3];
  CHECK_BOOL(kinematics->InverseKinematics(at, before), true);
  CHECK_BOOL(kinematics->InverseKinematics(moved, after), true);
  const double work = torques[0] * (after[0] - before[0]) + torques[1] * (after[1] - before[1]) + torques[2] * (after[2] - before[2]);
  const double expectedWork = 0.001 * vtkMath::Dot(force, step); // N m
  CHECK_DOUBLE_TOLERANCE(work, expectedWork, 1e-6 * std::abs(expectedWork));

  // Commands: proportional to the torques while they fit 16 bits.
  short commands[3];
  bool saturated = true;
  CHECK_BOOL(kinematics->ForceToMotorCommands(at, force, commands, saturated), true);
  CHECK_BOOL(saturated, false);
  for (int leg = 0; leg < 3; ++leg)
  {
    CHECK_DOUBLE_TOLERANCE(commands[leg], std::round(-10000.0 * torques[leg]), 0.0);
  }
  // A force far above what the motors give: all three scaled down together
  // (the direction is kept), none beyond the 16-bit range.
  const double huge[3] = { 150.0, -200.0, 300.0 };
  CHECK_BOOL(kinematics->ForceToMotorCommands(at, huge, commands, saturated), true);
  CHECK_BOOL(saturated, true);
  int largest = 0;
  for (int leg = 0; leg < 3; ++leg)
  {
    largest = std::max(largest, std::abs(static_cast<int>(commands[leg])));
  }
  CHECK_INT(largest, 32767);
  // huge is 100 x force: the commands keep the torques' ratios.
  for (int leg = 0; leg < 3; ++leg)
  {
    const double expected = commands[0] * torques[leg] / torques[0];
    CHECK_DOUBLE_TOLERANCE(commands[leg], expected, 1.0);
  }
  // A lower limit set by the application is kept too.
  kinematics->SetMaximumMotorCommand(4096);
  CHECK_BOOL(kinematics->ForceToMotorCommands(at, huge, commands, saturated), true);
  for (int leg = 0; leg < 3; ++leg)
  {
    CHECK_BOOL(std::abs(static_cast<int>(commands[leg])) <= 4096, true);
  }
  // Not a number: zero commands and a refusal.
  CHECK_BOOL(kinematics->ForceToMotorCommands(at, nan, commands, saturated), false);
  CHECK_INT(commands[0], 0);
  CHECK_INT(commands[1], 0);
  CHECK_INT(commands[2], 0);

  kinematics->Print(std::cout);
  return EXIT_SUCCESS;
}
