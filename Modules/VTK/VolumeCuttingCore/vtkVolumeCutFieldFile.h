// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutFieldFile
 * @brief   Reads and writes a cut field as a .vcut file, refusing damaged ones.
 *
 * A saved drilling session is the user's work: a file damaged on disk or in
 * transfer must never load as a different cut. The file ends with a CRC-32
 * (the checksum of zlib, gzip and PNG) of everything before it, and its size
 * must match what its header announces, so that byte flips, truncations and
 * overwritten headers are refused with a message naming the file, and the
 * field being read into keeps what it had.
 *
 * Layout, little-endian: magic "VCUTFLD\0", version (int32), anatomy
 * dimensions (3 x int32), sub-voxel factor (int32), anatomy IJK-to-RAS
 * (16 x float64), quantum (float64), brick count (int64), then per brick
 * its ID (int64) and its samples (BrickSize^3 x int16), then (version 2)
 * the CRC-32 (uint32). The band follows from the geometry. The undo history
 * and the shield are not stored: they follow from the session.
 *
 * Version 1 files (before the checksum) are still read, with a warning that
 * damage cannot be detected in them.
 */

#ifndef vtkVolumeCutFieldFile_h
#define vtkVolumeCutFieldFile_h

#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <cstddef> // For size_t
#include <cstdint> // For uint32_t

class vtkVolumeCutField;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutFieldFile : public vtkObject
{
public:
  static vtkVolumeCutFieldFile* New();
  vtkTypeMacro(vtkVolumeCutFieldFile, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The version this class writes.
  static constexpr int CurrentVersion = 2;

  ///@{
  /// Set/get the file to read or write. Default is none.
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  /**
   * Write the field (geometry and every allocated brick). A field that was
   * never initialized is written with zero dimensions. Returns false and
   * logs an error naming the file if it cannot be written.
   */
  bool Write(vtkVolumeCutField* field);

  /**
   * Read the file into the field. A missing, truncated, corrupt or foreign
   * file is refused with an error naming the file and what is wrong, and
   * the field keeps what it had.
   */
  bool Read(vtkVolumeCutField* field);

  /// Version of the file last read (0 before any).
  vtkGetMacro(LastReadVersion, int);

  /// CRC-32 (IEEE 802.3, as zlib's crc32) of data, continuing from crc.
  static uint32_t ComputeCRC32(const unsigned char* data, size_t length, uint32_t crc = 0);

protected:
  vtkVolumeCutFieldFile();
  ~vtkVolumeCutFieldFile() override;

  char* FileName = nullptr;
  int LastReadVersion = 0;

private:
  vtkVolumeCutFieldFile(const vtkVolumeCutFieldFile&) = delete;
  void operator=(const vtkVolumeCutFieldFile&) = delete;
};

#endif
