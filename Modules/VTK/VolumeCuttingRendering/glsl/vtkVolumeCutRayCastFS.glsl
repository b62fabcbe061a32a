//VTK::System::Dec
// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
//
// Adaptive multivolume ray casting (Pflesser et al.) on the GPU: the same
// algorithm, step for step, as vtkVolumeCutRayCaster's CPU reference, whose
// private headers document each stage. This skeleton sets up the pixel's ray
// and marches along it; vtkVolumeCutShaderComposer defines NUMBER_OF_CUTS and
// CUT_SLOTS (at least 1) and replaces each stage's tag (VolumeCut::<Stage>::Dec)
// with that stage's snippet, glsl/vtkVolumeCut<Stage>FS.glsl, as VTK's volume
// mappers compose their shaders (vtkVolumeShaderComposer.h).

//VTK::Output::Dec
in vec2 texCoord;

uniform sampler2D opaqueDepthTexture;
uniform vec3 dimensionsF;
uniform vec3 blockDimensionsF;
ivec3 dimensions;
ivec3 blockDimensions;
uniform mat4 ndcToWorld;
uniform mat4 worldToNDC;
uniform mat4 worldToIJK;
uniform mat4 ijkToWorld;
uniform mat3 normalMatrix;
// Millimetres per index unit across each axis's faces (1 / the norm of world-to-IJK's row).
uniform vec3 millimetresPerIndex;
uniform vec2 viewportSize;
uniform float sampleDistance;
uniform int blendMode;
uniform int cavityJumps;  // deep in a cavity, jump across the removed depth

#define BLOCK 8
#define SOURCE_OBJECT 1
#define SOURCE_BOX 2
#define SOURCE_PLANE 3
#define SOURCE_CUT 10

struct Sample
{
  float t;
  vec3 index;
  int object;
  float value;
  bool cutsKnown;
  float distance[CUT_SLOTS];
};

// The pixel's ray and what it has accumulated.
vec3 rayOrigin;     // IJK
vec3 rayDirection;  // IJK per mm
vec3 originWorld;
vec3 directionWorld;
vec4 accumulated = vec4(0.0);
bool firstHit = true;
float hitDepth = 1.0;
int layers = 0;
vec3 entryNormal;
vec3 viewVector;
bool insideVisible = false;

// ---- step 1: classification at a sample point
//VolumeCut::Classification::Dec
//VolumeCut::CutFields::Dec
//VolumeCut::EmptySpace::Dec
// ---- step 2: border location
//VolumeCut::BorderLocation::Dec
// ---- step 4: shading (with ambient occlusion and thin bone)
//VolumeCut::AmbientOcclusion::Dec
//VolumeCut::ThinBone::Dec
//VolumeCut::Shading::Dec
// ---- step 3: classification of pieces between borders
//VolumeCut::PieceClassification::Dec
// ---- composite mode
//VolumeCut::Composite::Dec

void main()
{
  dimensions = ivec3(dimensionsF + 0.5);
  blockDimensions = ivec3(blockDimensionsF + 0.5);
  //VolumeCut::CutField::Init
  // texCoord runs 0..1 across the viewport: pixel centres at (x + 0.5) / width.
  vec2 ndc = 2.0 * texCoord - 1.0;
  ivec2 pixel = ivec2(texCoord * viewportSize);
  vec4 nearH = ndcToWorld * vec4(ndc, -1.0, 1.0);
  vec4 farH = ndcToWorld * vec4(ndc, 1.0, 1.0);
  originWorld = nearH.xyz / nearH.w;
  directionWorld = farH.xyz / farH.w - originWorld;
  float tEnd = length(directionWorld);
  directionWorld /= tEnd;
  float opaque = texelFetch(opaqueDepthTexture, pixel, 0).r;
  if (opaque < 1.0)
  {
    vec4 hitH = ndcToWorld * vec4(ndc, 2.0 * opaque - 1.0, 1.0);
    tEnd = min(tEnd, length(hitH.xyz / hitH.w - originWorld));
  }
  viewVector = -directionWorld;
  rayOrigin = (worldToIJK * vec4(originWorld, 1.0)).xyz;
  rayDirection = mat3(worldToIJK) * directionWorld;

  float tStart = 0.0;
  entryNormal = viewVector;
  if (!clipToVolume(tStart, tEnd))
  {
    discard;
  }
  float voxelsPerMillimetre = length(rayDirection);
  float stepLength = sampleDistance / voxelsPerMillimetre;
  bool composite = blendMode == 1;

  Sample a = sampleAt(tStart);
  evaluateObject(a);
  if (composite)
  {
    evaluateCuts(a);
  }
  insideVisible = !composite && visible(a);
  bool done = insideVisible && enter(a, tStart, SOURCE_BOX);
  int lastCutBorder = -1;
  // A bound on the number of steps keeps a malformed camera from hanging the GPU.
  for (int guard = 0; !done && a.t < tEnd && guard < 1000000; ++guard)
  {
    if (blockEmpty(a.index) && (composite || a.object == 0))
    {
      float exitT = min(blockExit(a.index, a.t) + 1e-6, tEnd);
      if (exitT > a.t + stepLength)
      {
        a = sampleAt(exitT);
        evaluateObject(a);
        if (composite)
        {
          evaluateCuts(a);
          lastCutBorder = -1;
        }
        else
        {
          insideVisible = visible(a);
          done = insideVisible && enter(a, a.t, SOURCE_OBJECT);
        }
        continue;
      }
    }
    if (!composite)
    {
      // Where nothing can show ahead, the ray jumps to the last sample on
      // its sample grid before it may (the samples stay where a march
      // without the jump puts them, so that the same grazing rays catch a
      // surface's rim as on the CPU): through cells where nothing visible
      // can be, or deep in a cavity across the removed depth of this
      // sample.
      float clearUntil = a.t;
      if (a.object == 0)
      {
        clearUntil = exitEmptyCells(a.index, a.t, tEnd);
      }
      else if (cavityJumps != 0 && !insideVisible && a.cutsKnown)
      {
        clearUntil = removedDepthExit(a);
      }
      float landing = a.t + floor((min(clearUntil, tEnd) - a.t) / stepLength) * stepLength;
      if (landing > a.t + stepLength)
      {
        Sample landed = sampleAt(landing);
        evaluateObject(landed);
        bool landedVisible = visible(landed);
        // A jump across a removed depth that lands in visible material
        // overshot the cut's surface (vtkVolumeCutRayMarcher.cxx says why):
        // the ray marches on instead.
        if (!(landedVisible && a.object != 0))
        {
          a = landed;
          insideVisible = landedVisible;
          done = insideVisible && enter(a, a.t, SOURCE_OBJECT);
          continue;
        }
      }
    }
    Sample b = sampleAt(min(a.t + stepLength, tEnd));
    evaluateObject(b);
    if (!composite)
    {
      done = surfaceInterval(a, b, voxelsPerMillimetre);
      a = b;
      continue;
    }
    done = compositeStep(a, b, lastCutBorder);
    a = b;
  }
  if (accumulated.a <= 0.0)
  {
    discard;
  }
  gl_FragData[0] = accumulated;
  gl_FragDepth = hitDepth;
}
