// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldFile.h"

#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

namespace
{
// A real-data-like grid: non-round spacing, flipped x, oblique by 7 degrees.
void MakeGrid(vtkMatrix4x4* ijkToRas)
{
  const double angle = vtkMath::RadiansFromDegrees(7.0);
  const double spacing[3] = { 0.957031, 0.957031, 1.5 };
  ijkToRas->Identity();
  ijkToRas->SetElement(0, 0, -std::cos(angle) * spacing[0]);
  ijkToRas->SetElement(1, 0, std::sin(angle) * spacing[0]);
  ijkToRas->SetElement(0, 1, std::sin(angle) * spacing[1]);
  ijkToRas->SetElement(1, 1, std::cos(angle) * spacing[1]);
  ijkToRas->SetElement(2, 2, spacing[2]);
  ijkToRas->SetElement(0, 3, 122.3);
  ijkToRas->SetElement(1, 3, -97.91);
  ijkToRas->SetElement(2, 3, -61.25);
}

std::vector<char> ReadBytes(const std::string& path)
{
  std::ifstream stream(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::vector<char>& bytes)
{
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

bool SameSamples(vtkVolumeCutField* a, vtkVolumeCutField* b)
{
  if (a->GetNumberOfAllocatedBricks() != b->GetNumberOfAllocatedBricks())
  {
    return false;
  }
  const int* dims = a->GetBrickDimensions();
  short va[512];
  short vb[512];
  for (vtkIdType id = 0; id < static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2]; ++id)
  {
    a->CopyBrick(id, va);
    b->CopyBrick(id, vb);
    if (std::memcmp(va, vb, sizeof(va)) != 0)
    {
      return false;
    }
  }
  return true;
}
} // namespace

int vtkVolumeCutFieldFileTest1(int argc, char* argv[])
{
  const std::string folder = argc > 1 ? argv[argc - 1] : ".";
  // The standard check value of CRC-32 (zlib, PNG).
  const char* check = "123456789";
  CHECK_INT(static_cast<int>(vtkVolumeCutFieldFile::ComputeCRC32(reinterpret_cast<const unsigned char*>(check), 9) == 0xCBF43926u), 1);

  const int dims[3] = { 40, 36, 20 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);
  double a[4] = { 12.0, 15.0, 8.0, 1.0 };
  double b[4] = { 24.0, 19.0, 11.0, 1.0 };
  double p0[4];
  double p1[4];
  ijkToRas->MultiplyPoint(a, p0);
  ijkToRas->MultiplyPoint(b, p1);
  CHECK_BOOL(field->CutCapsule(p0, p1, 3.0), true);
  const double volume = field->ComputeRemovedVolume();

  const std::string path = folder + "/vtkVolumeCutFieldFileTest1.vcut";
  vtkNew<vtkVolumeCutFieldFile> file;
  file->SetFileName(path.c_str());
  CHECK_BOOL(file->Write(field), true);
  vtkNew<vtkVolumeCutField> read;
  CHECK_BOOL(file->Read(read), true);
  CHECK_INT(file->GetLastReadVersion(), 2);
  CHECK_BOOL(SameSamples(field, read), true);
  CHECK_DOUBLE_TOLERANCE(read->ComputeRemovedVolume(), volume, 1e-9 * volume);

  // Damage: byte flips anywhere, truncations, header overwrites, a longer
  // file. Every one is refused and the field read into keeps its cut.
  const std::vector<char> original = ReadBytes(path);
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(11);
  const std::string damagedPath = folder + "/vtkVolumeCutFieldFileTest1-damaged.vcut";
  int refused = 0;
  const int mutations = 150;
  for (int n = 0; n < mutations; ++n)
  {
    std::vector<char> bytes = original;
    const size_t position = static_cast<size_t>(random->GetNextValue() * (bytes.size() - 1));
    switch (n % 5)
    {
      case 0: // one byte flipped
      case 1:
        bytes[position] = static_cast<char>(bytes[position] ^ (1 + static_cast<int>(random->GetNextValue() * 254)));
        break;
      case 2: // truncated
        bytes.resize(position);
        break;
      case 3: // header overwritten with other bytes
      {
        const size_t start = static_cast<size_t>(random->GetNextValue() * 150);
        for (size_t k = start; k < start + 8; ++k)
        {
          bytes[k] = static_cast<char>(bytes[k] + 1 + static_cast<int>(random->GetNextValue() * 200));
        }
        break;
      }
      default: // garbage appended
        bytes.insert(bytes.end(), 1 + static_cast<int>(random->GetNextValue() * 2000), 'x');
        break;
    }
    WriteBytes(damagedPath, bytes);
    vtkNew<vtkVolumeCutFieldFile> damaged;
    damaged->SetFileName(damagedPath.c_str());
    TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
    const bool loaded = damaged->Read(read);
    TESTING_OUTPUT_ASSERT_ERRORS_END();
    refused += !loaded;
    if (!SameSamples(field, read))
    {
      std::cerr << "mutation " << n << " changed the field read into" << std::endl;
      return EXIT_FAILURE;
    }
  }
  std::cout << "damaged files refused: " << refused << " of " << mutations << std::endl;
  CHECK_INT(refused, mutations);

  // A version 1 file (no checksum) still reads, with a warning.
  std::vector<char> version1(original.begin(), original.end() - 4);
  const int32_t one = 1;
  std::memcpy(version1.data() + 8, &one, sizeof(one));
  const std::string oldPath = folder + "/vtkVolumeCutFieldFileTest1-v1.vcut";
  WriteBytes(oldPath, version1);
  vtkNew<vtkVolumeCutField> old;
  file->SetFileName(oldPath.c_str());
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  CHECK_BOOL(file->Read(old), true);
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_INT(file->GetLastReadVersion(), 1);
  CHECK_BOOL(SameSamples(field, old), true);

  // A missing file and a foreign one.
  file->SetFileName((folder + "/no-such-file.vcut").c_str());
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(file->Read(old), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  WriteBytes(damagedPath, std::vector<char>{ 'P', 'K', 3, 4 });
  file->SetFileName(damagedPath.c_str());
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(file->Read(old), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(SameSamples(field, old), true);

  // An empty field round-trips as empty.
  vtkNew<vtkVolumeCutField> empty;
  file->SetFileName(path.c_str());
  CHECK_BOOL(file->Write(empty), true);
  CHECK_BOOL(file->Read(old), true);
  CHECK_INT(old->GetDimensions()[0], 0);
  return EXIT_SUCCESS;
}
