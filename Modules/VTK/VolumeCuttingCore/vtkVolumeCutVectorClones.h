// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped).
//
// The cut field's writer runs a few loops once per brick sample of every
// stroke (tool distances, quantisation, merging). Functions marked
// VOLUMECUTTING_VECTOR_CLONES are built for AVX-512 and AVX2 besides the
// baseline, and the loader picks what the processor has (GCC 11 or later on
// Linux; elsewhere the baseline). Files using it are compiled without
// floating-point contraction (see CMakeLists.txt), so every variant rounds
// alike and replays stay bitwise reproducible across machines.
//
// Defining VOLUMECUTTING_VECTOR_CLONES empty builds the baseline alone, as
// ThreadSanitizer needs (its runtime is not up when the loader picks).
#ifndef vtkVolumeCutVectorClones_h
#define vtkVolumeCutVectorClones_h

#ifndef VOLUMECUTTING_VECTOR_CLONES
// GCC 11 is the first to know the x86-64-v3/v4 levels.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 11 && defined(__x86_64__) && defined(__linux__) && !defined(__SANITIZE_THREAD__)
#define VOLUMECUTTING_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define VOLUMECUTTING_VECTOR_CLONES
#endif
#endif

#endif
