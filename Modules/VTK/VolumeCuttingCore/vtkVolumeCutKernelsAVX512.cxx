// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Built for AVX-512 F/VL/BW/DQ (see CMakeLists.txt); used only where the processor has them.
#define VOLUMECUTTING_KERNELS_TABLE AVX512Table
#include "vtkVolumeCutKernelsImpl.h"
