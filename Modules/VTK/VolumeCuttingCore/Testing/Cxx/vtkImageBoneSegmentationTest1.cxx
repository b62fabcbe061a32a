// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkImageBoneSegmentation.h"

#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkShortArray.h>

#include <cmath>
#include <limits>

namespace
{
// A bone ball in a world frame with anisotropic voxels: a cortical shell
// (inner radius 8 mm, outer 12 mm) around trabecular bone, plus two blobs
// outside it: a trabecular-bright one that no cortical seed reaches (must stay
// background) and a small cortical one (its own seed, so bone).
const double Center[3] = { 20.0, 20.0, 21.0 };
const double InnerRadius = 8.0;
const double OuterRadius = 12.0;
const double LooseBlobCenter[3] = { 34.0, 34.0, 21.0 };
const double DenseBlobCenter[3] = { 5.0, 5.0, 21.0 };
const double BlobRadius = 2.5;

double Distance(const double a[3], const double b[3])
{
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

enum Truth
{
  Air,
  Cortical,
  Trabecular
};

Truth Classify(const double p[3])
{
  const double r = Distance(p, Center);
  if (r <= InnerRadius)
  {
    return Trabecular;
  }
  if (r <= OuterRadius || Distance(p, DenseBlobCenter) <= BlobRadius)
  {
    return Cortical;
  }
  return Air;
}

void MakePhantom(vtkImageData* image)
{
  image->SetDimensions(41, 41, 28);
  image->SetSpacing(1.0, 1.0, 1.5);
  image->SetOrigin(0.0, 0.0, 0.0);
  image->AllocateScalars(VTK_SHORT, 1);
  short* voxels = static_cast<short*>(image->GetScalarPointer());
  const int* dims = image->GetDimensions();
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        double p[3];
        image->TransformIndexToPhysicalPoint(i, j, k, p);
        short value = -1000;
        switch (Classify(p))
        {
          case Cortical: value = 1600; break;
          case Trabecular: value = 450; break;
          default:
            value = Distance(p, LooseBlobCenter) <= BlobRadius ? 450 : -1000;
        }
        voxels[(k * dims[1] + j) * dims[0] + i] = value;
      }
    }
  }
}

int TestAgainstAnalyticBall()
{
  vtkNew<vtkImageData> image;
  MakePhantom(image);
  vtkNew<vtkImageBoneSegmentation> segmentation;
  segmentation->SetInputData(image);
  segmentation->Update();
  vtkImageData* labels = segmentation->GetOutput();
  CHECK_INT(labels->GetScalarType(), VTK_UNSIGNED_CHAR);
  CHECK_DOUBLE(labels->GetSpacing()[2], 1.5);

  vtkIdType expectedCortical = 0;
  vtkIdType expectedTrabecular = 0;
  const int* dims = image->GetDimensions();
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        double p[3];
        image->TransformIndexToPhysicalPoint(i, j, k, p);
        const Truth truth = Classify(p);
        const int expected = truth == Cortical ? vtkImageBoneSegmentation::CorticalLabel
          : truth == Trabecular                ? vtkImageBoneSegmentation::TrabecularLabel
                                               : vtkImageBoneSegmentation::BackgroundLabel;
        expectedCortical += truth == Cortical;
        expectedTrabecular += truth == Trabecular;
        const int actual = static_cast<int>(labels->GetScalarComponentAsDouble(i, j, k, 0));
        if (actual != expected)
        {
          std::cerr << "Voxel " << i << "," << j << "," << k << ": label " << actual << ", expected " << expected << std::endl;
          return EXIT_FAILURE;
        }
      }
    }
  }
  CHECK_BOOL(expectedCortical > 1000 && expectedTrabecular > 1000, true);
  CHECK_INT(segmentation->GetNumberOfCorticalVoxels(), expectedCortical);
  CHECK_INT(segmentation->GetNumberOfTrabecularVoxels(), expectedTrabecular);

  // The analytic volume of the trabecular ball is matched by the voxel count
  // within the discretisation error of a sphere of 8 voxels radius.
  const double voxelVolume = 1.0 * 1.0 * 1.5;
  const double exactTrabecular = 4.0 / 3.0 * 3.14159265358979 * std::pow(InnerRadius, 3);
  const double relativeError = std::abs(expectedTrabecular * voxelVolume - exactTrabecular) / exactTrabecular;
  CHECK_BOOL(relativeError < 0.05, true);
  return EXIT_SUCCESS;
}

int TestSmoothingAndDirection()
{
  vtkNew<vtkImageData> image;
  MakePhantom(image);
  vtkNew<vtkMatrix3x3> direction;
  direction->SetElement(0, 0, 0.0);
  direction->SetElement(0, 1, -1.0);
  direction->SetElement(1, 0, 1.0);
  direction->SetElement(1, 1, 0.0);
  image->SetDirectionMatrix(direction);

  vtkNew<vtkImageBoneSegmentation> segmentation;
  segmentation->SetInputData(image);
  segmentation->SetSmoothingStandardDeviation(0.8);
  segmentation->Update();
  vtkImageData* labels = segmentation->GetOutput();
  CHECK_DOUBLE(labels->GetDirectionMatrix()->GetElement(0, 1), -1.0);
  // Smoothing blurs the 3-voxel-wide shell boundary but keeps the ball: the
  // centre is trabecular, the middle of the shell cortical, far away air.
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(20, 20, 14, 0)), vtkImageBoneSegmentation::TrabecularLabel);
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(30, 20, 14, 0)), vtkImageBoneSegmentation::CorticalLabel);
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(0, 40, 0, 0)), vtkImageBoneSegmentation::BackgroundLabel);
  return EXIT_SUCCESS;
}

// A bone ball as a CT scans it: a cortex (1500 HU) from 6 to 10 mm around
// trabecular bone (450 HU), its outer boundary a partial-volume ramp down to
// air over 2 mm, so the voxels the boundary crosses have trabecular-range
// values. The paper's model (cortical boundary, trabecular interior) wants
// them cortical. The interior, an air cell in its middle (2 mm), stays
// trabecular: bone around air but away from the cortex is not its shell.
int TestPartialVolumeShell()
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(31, 31, 31);
  image->AllocateScalars(VTK_SHORT, 1);
  short* voxels = static_cast<short*>(image->GetScalarPointer());
  const double center[3] = { 15.2, 14.9, 15.1 };
  for (int k = 0; k < 31; ++k)
  {
    for (int j = 0; j < 31; ++j)
    {
      for (int i = 0; i < 31; ++i)
      {
        const double p[3] = { double(i), double(j), double(k) };
        const double r = Distance(p, center);
        const double value = r <= 2.0 ? -1000.0
          : r <= 6.0                 ? 450.0
          : r <= 10.0                ? 1500.0
          : r >= 12.0                ? -1000.0
                                     : 1500.0 - 2500.0 * (r - 10.0) / 2.0;
        voxels[(k * 31 + j) * 31 + i] = static_cast<short>(value);
      }
    }
  }
  for (bool boundaryIsCortical : { false, true })
  {
    vtkNew<vtkImageBoneSegmentation> segmentation;
    segmentation->SetInputData(image);
    segmentation->SetBoundaryIsCortical(boundaryIsCortical);
    segmentation->Update();
    vtkImageData* labels = segmentation->GetOutput();
    vtkIdType rampVoxels = 0;
    vtkIdType rampCortical = 0;
    vtkIdType counted[3] = { 0, 0, 0 };
    for (int k = 0; k < 31; ++k)
    {
      for (int j = 0; j < 31; ++j)
      {
        for (int i = 0; i < 31; ++i)
        {
          const double p[3] = { double(i), double(j), double(k) };
          const double r = Distance(p, center);
          const int label = static_cast<int>(labels->GetScalarComponentAsDouble(i, j, k, 0));
          ++counted[label];
          if (r > 2.0 && r <= 5.0)
          {
            CHECK_INT(label, vtkImageBoneSegmentation::TrabecularLabel);
          }
          const short value = voxels[(k * 31 + j) * 31 + i];
          if (r > 10.0 && value >= 200 && value < 700)
          {
            ++rampVoxels;
            rampCortical += label == vtkImageBoneSegmentation::CorticalLabel;
          }
        }
      }
    }
    CHECK_BOOL(rampVoxels > 200, true);
    CHECK_INT(rampCortical, boundaryIsCortical ? rampVoxels : 0);
    CHECK_INT(segmentation->GetNumberOfCorticalVoxels(), counted[vtkImageBoneSegmentation::CorticalLabel]);
    CHECK_INT(segmentation->GetNumberOfTrabecularVoxels(), counted[vtkImageBoneSegmentation::TrabecularLabel]);
  }
  return EXIT_SUCCESS;
}

int TestBadInput()
{
  vtkNew<vtkImageBoneSegmentation> segmentation;

  // No voxel values.
  vtkNew<vtkImageData> empty;
  segmentation->SetInputData(empty);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  segmentation->Update();
  TESTING_OUTPUT_ASSERT_ERRORS_END();

  // Thresholds in the wrong order.
  vtkNew<vtkImageData> image;
  MakePhantom(image);
  segmentation->SetInputData(image);
  segmentation->SetTrabecularThreshold(2000);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  segmentation->Update();
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  segmentation->SetTrabecularThreshold(200);

  // NaN voxels in a float CT are never bone and never bridge regions.
  vtkNew<vtkImageData> floatImage;
  floatImage->SetDimensions(5, 1, 1);
  floatImage->AllocateScalars(VTK_FLOAT, 1);
  float* values = static_cast<float*>(floatImage->GetScalarPointer());
  const float row[5] = { 1500.f, std::numeric_limits<float>::quiet_NaN(), 400.f, 400.f, 1500.f };
  std::copy(row, row + 5, values);
  values[4] = -1000.f;
  vtkNew<vtkImageBoneSegmentation> floatSegmentation;
  floatSegmentation->SetInputData(floatImage);
  floatSegmentation->Update();
  vtkImageData* labels = floatSegmentation->GetOutput();
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(0, 0, 0, 0)), vtkImageBoneSegmentation::CorticalLabel);
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(1, 0, 0, 0)), vtkImageBoneSegmentation::BackgroundLabel);
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(2, 0, 0, 0)), vtkImageBoneSegmentation::BackgroundLabel);
  CHECK_INT(static_cast<int>(labels->GetScalarComponentAsDouble(3, 0, 0, 0)), vtkImageBoneSegmentation::BackgroundLabel);
  return EXIT_SUCCESS;
}
} // namespace

int vtkImageBoneSegmentationTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestAgainstAnalyticBall());
  CHECK_EXIT_SUCCESS(TestSmoothingAndDirection());
  CHECK_EXIT_SUCCESS(TestPartialVolumeShell());
  CHECK_EXIT_SUCCESS(TestBadInput());

  vtkNew<vtkImageBoneSegmentation> segmentation;
  std::stringstream printed;
  segmentation->Print(printed);
  CHECK_BOOL(printed.str().find("CorticalThreshold: 700") != std::string::npos, true);
  CHECK_BOOL(printed.str().find("BoundaryIsCortical: 1") != std::string::npos, true);
  return EXIT_SUCCESS;
}
