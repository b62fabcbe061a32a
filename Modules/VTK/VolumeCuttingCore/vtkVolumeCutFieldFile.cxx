// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutFieldFile.h"
#include "vtkVolumeCutField.h"

#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutFieldFile);

namespace
{
constexpr char Magic[8] = { 'V', 'C', 'U', 'T', 'F', 'L', 'D', '\0' };
constexpr int SamplesPerBrick = vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize;
// magic, version, dimensions, factor, matrix, quantum, brick count
constexpr size_t HeaderSize = sizeof(Magic) + 4 + 3 * 4 + 4 + 16 * 8 + 8 + 8;
constexpr size_t BrickRecordSize = 8 + SamplesPerBrick * sizeof(int16_t);

/// Slicing-by-8 tables of the reflected IEEE polynomial.
const std::array<std::array<uint32_t, 256>, 8>& CRCTables()
{
  static const std::array<std::array<uint32_t, 256>, 8> tables = [] {
    std::array<std::array<uint32_t, 256>, 8> t{};
    for (uint32_t n = 0; n < 256; ++n)
    {
      uint32_t c = n;
      for (int bit = 0; bit < 8; ++bit)
      {
        c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      }
      t[0][n] = c;
    }
    for (uint32_t n = 0; n < 256; ++n)
    {
      for (int slice = 1; slice < 8; ++slice)
      {
        t[slice][n] = (t[slice - 1][n] >> 8) ^ t[0][t[slice - 1][n] & 0xFFu];
      }
    }
    return t;
  }();
  return tables;
}

/// Appends values to a byte buffer in little-endian order (the machines
/// this runs on are little-endian; checked where the buffer is written).
template <typename T>
void Append(std::vector<unsigned char>& buffer, const T& value)
{
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(&value);
  buffer.insert(buffer.end(), bytes, bytes + sizeof(T));
}

/// Reads values from a byte buffer, refusing to read past its end.
class Reader
{
public:
  Reader(const unsigned char* data, size_t size)
    : Data(data)
    , Size(size)
  {
  }
  template <typename T>
  bool Read(T& value)
  {
    return this->ReadBytes(&value, sizeof(T));
  }
  bool ReadBytes(void* target, size_t count)
  {
    if (this->Position + count > this->Size)
    {
      return false;
    }
    std::memcpy(target, this->Data + this->Position, count);
    this->Position += count;
    return true;
  }

private:
  const unsigned char* Data;
  size_t Size;
  size_t Position = 0;
};

bool IsLittleEndian()
{
  const uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}
} // namespace

//------------------------------------------------------------------------------
vtkVolumeCutFieldFile::vtkVolumeCutFieldFile() = default;

//------------------------------------------------------------------------------
vtkVolumeCutFieldFile::~vtkVolumeCutFieldFile()
{
  this->SetFileName(nullptr);
}

//------------------------------------------------------------------------------
uint32_t vtkVolumeCutFieldFile::ComputeCRC32(const unsigned char* data, size_t length, uint32_t crc)
{
  const auto& t = CRCTables();
  uint32_t c = ~crc;
  while (length >= 8)
  {
    const uint32_t low = c ^ (uint32_t(data[0]) | uint32_t(data[1]) << 8 | uint32_t(data[2]) << 16 | uint32_t(data[3]) << 24);
    c = t[7][low & 0xFFu] ^ t[6][(low >> 8) & 0xFFu] ^ t[5][(low >> 16) & 0xFFu] ^ t[4][low >> 24] ^ t[3][data[4]] ^ t[2][data[5]] ^
      t[1][data[6]] ^ t[0][data[7]];
    data += 8;
    length -= 8;
  }
  while (length-- > 0)
  {
    c = t[0][(c ^ *data++) & 0xFFu] ^ (c >> 8);
  }
  return ~c;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutFieldFile::Write(vtkVolumeCutField* field)
{
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("Write: no file name");
    return false;
  }
  if (!field)
  {
    vtkErrorMacro("Write: no cut field to write to " << this->FileName);
    return false;
  }
  if (!IsLittleEndian())
  {
    vtkErrorMacro("Write: .vcut files are little-endian; this processor is not");
    return false;
  }
  const int f = std::max(field->SubVoxelFactor, 1);
  const vtkIdType count = field->Directory ? field->NumberOfAllocatedBricks.load(std::memory_order_acquire) : 0;
  std::vector<unsigned char> buffer;
  buffer.reserve(HeaderSize + static_cast<size_t>(count) * BrickRecordSize + 4);
  buffer.insert(buffer.end(), Magic, Magic + sizeof(Magic));
  Append(buffer, static_cast<int32_t>(CurrentVersion));
  for (int axis = 0; axis < 3; ++axis)
  {
    Append(buffer, static_cast<int32_t>(field->Dimensions[axis] / f));
  }
  Append(buffer, static_cast<int32_t>(field->Directory ? f : 0));
  for (double element : field->AnatomyIJKToRAS)
  {
    Append(buffer, element);
  }
  Append(buffer, field->Quantum);
  Append(buffer, static_cast<int64_t>(count));
  short values[SamplesPerBrick];
  for (vtkIdType n = 0; n < count; ++n)
  {
    const vtkIdType brickId = field->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    field->CopyBrick(brickId, values);
    Append(buffer, static_cast<int64_t>(brickId));
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(values);
    buffer.insert(buffer.end(), bytes, bytes + sizeof(values));
  }
  Append(buffer, ComputeCRC32(buffer.data(), buffer.size()));

  std::ofstream stream(this->FileName, std::ios::binary | std::ios::trunc);
  if (!stream)
  {
    vtkErrorMacro("Write: cannot open " << this->FileName << " for writing");
    return false;
  }
  stream.write(reinterpret_cast<const char*>(buffer.data()), static_cast<std::streamsize>(buffer.size()));
  if (!stream.flush())
  {
    vtkErrorMacro("Write: writing " << this->FileName << " failed (disk full?)");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutFieldFile::Read(vtkVolumeCutField* field)
{
  const char* name = this->FileName ? this->FileName : "(no file name)";
  if (!field)
  {
    vtkErrorMacro("Read: no cut field to read " << name << " into");
    return false;
  }
  std::ifstream stream(this->FileName ? this->FileName : "", std::ios::binary | std::ios::ate);
  if (!this->FileName || !stream)
  {
    vtkErrorMacro("Read: cannot open " << name);
    return false;
  }
  const std::streamoff size = stream.tellg();
  std::vector<unsigned char> data(size > 0 ? static_cast<size_t>(size) : 0);
  stream.seekg(0);
  if (size < 0 || !stream.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size())))
  {
    vtkErrorMacro("Read: cannot read " << name);
    return false;
  }
  Reader reader(data.data(), data.size());
  char magic[sizeof(Magic)];
  int32_t version = 0;
  if (!reader.ReadBytes(magic, sizeof(magic)) || std::memcmp(magic, Magic, sizeof(magic)) != 0 || !reader.Read(version) || version < 1 ||
    version > CurrentVersion)
  {
    vtkErrorMacro("Read: " << name << " is not a cut field file (version 1 to " << CurrentVersion << "); it was not loaded");
    return false;
  }
  int32_t anatomyDimensions[3];
  int32_t factor = 0;
  double matrixElements[16];
  double quantum = 0.0;
  int64_t count = 0;
  bool ok = reader.Read(anatomyDimensions[0]) && reader.Read(anatomyDimensions[1]) && reader.Read(anatomyDimensions[2]) && reader.Read(factor);
  for (double& element : matrixElements)
  {
    ok = ok && reader.Read(element);
  }
  ok = ok && reader.Read(quantum) && reader.Read(count);
  if (!ok)
  {
    vtkErrorMacro("Read: " << name << " is truncated (" << data.size() << " bytes, shorter than its header); it was not loaded");
    return false;
  }
  if (version >= 2)
  {
    // The size the header announces, then the checksum of all before it.
    const size_t expected = count >= 0 && static_cast<uint64_t>(count) < (uint64_t(1) << 40) / BrickRecordSize
      ? HeaderSize + static_cast<size_t>(count) * BrickRecordSize + 4
      : 0;
    if (data.size() != expected)
    {
      vtkErrorMacro("Read: " << name << " is damaged: " << data.size() << " bytes where its header announces " << expected
                             << " (truncated or overwritten); it was not loaded and the cut was kept as it was");
      return false;
    }
    uint32_t stored;
    std::memcpy(&stored, data.data() + data.size() - 4, 4);
    const uint32_t computed = ComputeCRC32(data.data(), data.size() - 4);
    if (stored != computed)
    {
      vtkErrorMacro("Read: " << name << " is damaged (checksum mismatch); it was not loaded and the cut was kept as it was");
      return false;
    }
  }
  else
  {
    vtkWarningMacro("Read: " << name << " is a version 1 cut field file, which has no checksum: damage to it cannot be detected. Save the scene again to add one.");
  }
  this->LastReadVersion = version;

  if (anatomyDimensions[0] == 0 && anatomyDimensions[1] == 0 && anatomyDimensions[2] == 0 && count == 0)
  {
    vtkNew<vtkVolumeCutField> empty; // a field that was never initialized
    field->DeepCopy(empty);
    return true;
  }
  vtkNew<vtkVolumeCutField> loaded;
  vtkNew<vtkMatrix4x4> ijkToRas;
  ijkToRas->DeepCopy(matrixElements);
  const int dimensions[3] = { anatomyDimensions[0], anatomyDimensions[1], anatomyDimensions[2] };
  if (!loaded->Initialize(dimensions, ijkToRas, factor))
  {
    vtkErrorMacro("Read: " << name << " holds an invalid geometry; it was not loaded");
    return false;
  }
  const vtkIdType totalBricks = static_cast<vtkIdType>(loaded->BrickDimensions[0]) * loaded->BrickDimensions[1] * loaded->BrickDimensions[2];
  if (std::abs(quantum - loaded->Quantum) > 1e-12 * std::max(1.0, loaded->Quantum) || count < 0 || count > totalBricks)
  {
    vtkErrorMacro("Read: " << name << " is inconsistent (quantum or brick count); it was not loaded");
    return false;
  }
  vtkVolumeCutField::BrickStates bricks;
  for (int64_t n = 0; n < count; ++n)
  {
    int64_t brickId = -1;
    vtkVolumeCutField::BrickValues values(SamplesPerBrick);
    if (!reader.Read(brickId) || !reader.ReadBytes(values.data(), SamplesPerBrick * sizeof(int16_t)))
    {
      vtkErrorMacro("Read: " << name << " is truncated (brick " << n << " of " << count << "); it was not loaded");
      return false;
    }
    if (brickId < 0 || brickId >= totalBricks || bricks.count(static_cast<vtkIdType>(brickId)))
    {
      vtkErrorMacro("Read: " << name << " names a brick outside the volume or twice; it was not loaded");
      return false;
    }
    bricks[static_cast<vtkIdType>(brickId)] = std::move(values);
  }
  loaded->WriteBricks(bricks);
  field->DeepCopy(loaded);
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutFieldFile::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "LastReadVersion: " << this->LastReadVersion << "\n";
}
