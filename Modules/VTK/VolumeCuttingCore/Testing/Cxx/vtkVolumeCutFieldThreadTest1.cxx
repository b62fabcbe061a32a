// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The cut field's reader/writer contract; also run under ThreadSanitizer
// (Utilities/vc test builds build/tsan for it).
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"

#include <vtkAddonTestingMacros.h>

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <vtkSmartPointer.h>

#include <algorithm>
#include <atomic>
#include <thread>

namespace
{
// One writer cutting while a reader copies the brick it cuts through: with
// cuts only, no stored sample may ever grow, and a copy is never half-written
// (a torn copy would mix samples of two states and could show one grow).
int TestConcurrentReaderAndWriter()
{
  const int dims[3] = { 48, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  for (int axis = 0; axis < 3; ++axis)
  {
    ijkToRas->SetElement(axis, axis, 0.5);
  }
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  const double watched[4] = { 12.0, 12.0, 12.0, 1.0 };
  vtkNew<vtkMatrix4x4> subToRas;
  vtkNew<vtkMatrix4x4> rasToSub;
  field->GetSubVoxelIJKToRAS(subToRas);
  vtkMatrix4x4::Invert(subToRas, rasToSub);
  double index[4];
  rasToSub->MultiplyPoint(watched, index);
  const int* brickDims = field->GetBrickDimensions();
  const int b[3] = { int(index[0]) / vtkVolumeCutField::BrickSize, int(index[1]) / vtkVolumeCutField::BrickSize,
    int(index[2]) / vtkVolumeCutField::BrickSize };
  const vtkIdType brickId = (static_cast<vtkIdType>(b[2]) * brickDims[1] + b[1]) * brickDims[0] + b[0];

  std::atomic<bool> done{ false };
  std::atomic<bool> consistent{ true };
  std::atomic<int> copies{ 0 };
  std::thread reader([&]() {
    short previous[512];
    short current[512];
    vtkTypeUInt64 previousStamp = field->CopyBrick(brickId, previous);
    while (!done.load())
    {
      const vtkTypeUInt64 stamp = field->CopyBrick(brickId, current);
      for (int n = 0; n < 512; ++n)
      {
        if (current[n] > previous[n] || stamp < previousStamp)
        {
          consistent = false;
        }
      }
      std::copy(current, current + 512, previous);
      previousStamp = stamp;
      field->GetSignedDistance(watched);
      ++copies;
    }
  });
  for (int n = 0; n < 400; ++n)
  {
    const double t = n / 400.0;
    const double p0[3] = { 4.0 + 16.0 * t, 12.0, 12.0 };
    const double p1[3] = { 4.0 + 16.0 * (t + 1.0 / 400.0), 12.0, 12.0 };
    field->CutCapsule(p0, p1, 1.5);
  }
  done = true;
  reader.join();
  CHECK_BOOL(consistent.load(), true);
  CHECK_BOOL(copies.load() > 0, true);
  CHECK_BOOL(field->GetSignedDistance(watched) < 0.0, true);
  return EXIT_SUCCESS;
}

// A field with a shielded column, cut along it by a capsule's steps.
void CutAlongShield(vtkVolumeCutField* field, int steps, int first, int last)
{
  for (int n = first; n < last; ++n)
  {
    const double p0[3] = { 2.0 + 20.0 * n / steps, 9.0, 12.0 };
    const double p1[3] = { 2.0 + 20.0 * (n + 1) / steps, 9.0, 12.0 };
    field->CutCapsule(p0, p1, 1.5);
  }
}

vtkSmartPointer<vtkVolumeCutField> ShieldedField(vtkImageData* labels)
{
  const int dims[3] = { 48, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  for (int axis = 0; axis < 3; ++axis)
  {
    ijkToRas->SetElement(axis, axis, 0.5);
  }
  auto field = vtkSmartPointer<vtkVolumeCutField>::New();
  field->Initialize(dims, ijkToRas, 2);
  field->SetProtectedLabels(labels);
  return field;
}

// The writer cuts beside a shielded column while a preparer builds the
// shield ahead of it (the haptic loop's preparer): the writer takes the
// prepared bricks without waiting, and the cut is the one of a writer that
// built every brick itself.
int TestPreparerAheadOfWriter()
{
  vtkNew<vtkImageData> labels;
  labels->SetDimensions(48, 48, 48);
  labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  std::fill_n(static_cast<unsigned char*>(labels->GetScalarPointer()), 48 * 48 * 48, 0);
  for (int i = 0; i < 48; ++i)
  {
    for (int k = 22; k < 26; ++k)
    {
      labels->SetScalarComponentFromDouble(i, 22, k, 0, 1); // a rod along x at y = 11, z = 12 mm
    }
  }
  const int steps = 200;
  vtkSmartPointer<vtkVolumeCutField> alone = ShieldedField(labels);
  alone->BeginStroke();
  CutAlongShield(alone, steps, 0, steps);
  alone->EndStroke();
  CHECK_BOOL(alone->GetProtection()->GetNumberOfBricksBuiltOnDemand() > 0, true);

  vtkSmartPointer<vtkVolumeCutField> field = ShieldedField(labels);
  std::atomic<int> position{ 0 };
  std::atomic<bool> done{ false };
  std::atomic<vtkIdType> prepared{ 0 };
  std::thread preparer([&]() {
    while (!done.load())
    {
      const double center[3] = { 2.0 + 20.0 * position.load() / steps, 9.0, 12.0 };
      prepared += field->PrepareProtectionAhead(center, 1.5 + 3.0);
      std::this_thread::yield();
    }
  });
  // The first steps wait for the preparer's first ring, as a tool's approach leaves it time to.
  while (field->GetProtection()->GetNumberOfPreparedBricks() == 0)
  {
    std::this_thread::yield();
  }
  field->BeginStroke();
  for (int n = 0; n < steps; ++n)
  {
    position = n;
    CutAlongShield(field, steps, n, n + 1);
  }
  field->EndStroke();
  done = true;
  preparer.join();
  CHECK_BOOL(prepared.load() > 0, true);
  // The same cut, whoever built the shield.
  for (double x = 1.0; x < 23.0; x += 0.25)
  {
    for (double z = 9.0; z < 15.0; z += 0.25)
    {
      const double point[3] = { x, 9.0 + 1.2, z };
      CHECK_DOUBLE_TOLERANCE(field->GetSignedDistance(point), alone->GetSignedDistance(point), 1e-9);
    }
  }
  // Clearing forgets what was prepared too.
  field->GetProtection()->ClearBricks();
  CHECK_INT(static_cast<int>(field->GetProtection()->GetNumberOfPreparedBricks()), 0);
  CHECK_INT(static_cast<int>(field->GetProtection()->GetNumberOfBuiltBricks()), 0);
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutFieldThreadTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestConcurrentReaderAndWriter());
  CHECK_EXIT_SUCCESS(TestPreparerAheadOfWriter());
  return EXIT_SUCCESS;
}
