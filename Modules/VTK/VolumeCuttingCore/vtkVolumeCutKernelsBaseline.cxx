// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Built with the compiler's default instruction set: the kernels every processor runs.
#define VOLUMECUTTING_KERNELS_TABLE BaselineTable
#include "vtkVolumeCutKernelsImpl.h"
