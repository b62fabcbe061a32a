// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutKernels.h"

#include <atomic>

#if defined(_MSC_VER) && !defined(__clang__) && (defined(_M_X64) || defined(_M_IX86))
#include <immintrin.h>
#include <intrin.h>
#endif

namespace
{
/// Whether the processor and the operating system (which must save the wider
/// registers on a context switch) run the set. Asked once per set.
bool ProcessorRuns(int set)
{
  if (set == vtkVolumeCutKernels::Baseline)
  {
    return true;
  }
#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
  // These consult XGETBV as well as CPUID.
  __builtin_cpu_init();
  if (set == vtkVolumeCutKernels::AVX2)
  {
    return __builtin_cpu_supports("avx2");
  }
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
    __builtin_cpu_supports("avx512dq");
#elif defined(_MSC_VER) && (defined(_M_X64) || defined(_M_IX86))
  int registers[4];
  __cpuid(registers, 0);
  if (registers[0] < 7)
  {
    return false;
  }
  __cpuid(registers, 1);
  const bool osSavesVectorState = (registers[2] & (1 << 27)) != 0;
  const bool fma = (registers[2] & (1 << 12)) != 0; // /arch:AVX2 may use it
  if (!osSavesVectorState || !fma)
  {
    return false;
  }
  const unsigned long long enabled = _xgetbv(0);
  __cpuidex(registers, 7, 0);
  const unsigned int features = static_cast<unsigned int>(registers[1]);
  const bool ymm = (enabled & 0x6) == 0x6;
  if (set == vtkVolumeCutKernels::AVX2)
  {
    return ymm && (features & (1u << 5)) != 0;
  }
  const bool zmm = (enabled & 0xE6) == 0xE6;
  const unsigned int avx512 = (1u << 16) | (1u << 17) | (1u << 30) | (1u << 31); // F, DQ, BW, VL
  return zmm && (features & avx512) == avx512;
#else
  return false;
#endif
}

const vtkVolumeCutKernels::Table* CompiledTable(int set)
{
  switch (set)
  {
    case vtkVolumeCutKernels::Baseline:
      return &vtkVolumeCutKernels::BaselineTable;
#ifdef VOLUMECUTTING_KERNELS_HAVE_AVX2
    case vtkVolumeCutKernels::AVX2:
      return &vtkVolumeCutKernels::AVX2Table;
#endif
#ifdef VOLUMECUTTING_KERNELS_HAVE_AVX512
    case vtkVolumeCutKernels::AVX512:
      return &vtkVolumeCutKernels::AVX512Table;
#endif
    default:
      return nullptr;
  }
}

struct Selection
{
  Selection()
  {
    for (int set = 0; set < vtkVolumeCutKernels::NumberOfInstructionSets; ++set)
    {
      this->Available[set] = CompiledTable(set) != nullptr && ProcessorRuns(set);
      if (this->Available[set])
      {
        this->Set.store(set, std::memory_order_relaxed);
      }
    }
  }
  bool Available[vtkVolumeCutKernels::NumberOfInstructionSets];
  // The haptic thread reads it for every brick; another thread may switch
  // sets (benchmarks, tests): every set computes the same values.
  std::atomic<int> Set{ vtkVolumeCutKernels::Baseline };
};

Selection& GetSelection()
{
  static Selection selection; // thread-safe initialisation
  return selection;
}
}

//------------------------------------------------------------------------------
const vtkVolumeCutKernels::Table& vtkVolumeCutKernels::Get()
{
  return *CompiledTable(GetSelection().Set.load(std::memory_order_relaxed));
}

//------------------------------------------------------------------------------
bool vtkVolumeCutKernels::IsAvailable(int set)
{
  return set >= 0 && set < NumberOfInstructionSets && GetSelection().Available[set];
}

//------------------------------------------------------------------------------
bool vtkVolumeCutKernels::Select(int set)
{
  if (!IsAvailable(set))
  {
    return false;
  }
  GetSelection().Set.store(set, std::memory_order_relaxed);
  return true;
}

//------------------------------------------------------------------------------
int vtkVolumeCutKernels::GetSelected()
{
  return GetSelection().Set.load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutKernels::GetName(int set)
{
  switch (set)
  {
    case Baseline:
      return "baseline";
    case AVX2:
      return "AVX2";
    case AVX512:
      return "AVX-512";
    default:
      return "unknown";
  }
}
