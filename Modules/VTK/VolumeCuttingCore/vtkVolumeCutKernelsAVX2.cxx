// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Built for AVX2 (see CMakeLists.txt); used only where the processor has it.
#define VOLUMECUTTING_KERNELS_TABLE AVX2Table
#include "vtkVolumeCutKernelsImpl.h"
