//VTK::System::Dec
// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
//
// Adaptive multivolume ray casting (Pflesser et al.) on the GPU: the same
// algorithm, step for step, as vtkVolumeCutRayCaster's CPU reference, which
// documents it. The host defines NUMBER_OF_CUTS and CUT_SLOTS (at least 1) and
// replaces the //VolumeCut:: markers with one copy of the per-cut-field code
// for each field (vtkVolumeCutOpenGLRayCaster.cxx).

//VTK::Output::Dec
in vec2 texCoord;

uniform sampler3D anatomyTexture;   // CT (R32F), fetched texel by texel
uniform sampler3D labelTexture;     // labels (R32F), when hasLabels
uniform sampler2D styleTexture;     // per label: (rgb, opacity), (iso, shape, 0, 0)
uniform sampler3D blockTexture;     // per 8^3 block: (occupied, gradient bound)
uniform sampler2D opaqueDepthTexture;
uniform sampler2D transferTexture;  // composite mode: (rgb, opacity per unit distance)

uniform int hasLabels;             // a label map or fractional labelmaps
uniform int hasLabelMap;
uniform sampler3D fractionTexture;  // up to 4 segments' fractions (RGBA)
uniform int fractionCount;
uniform vec4 fractionLabels;
uniform int styleCount;
uniform vec3 dimensionsF;
uniform vec3 blockDimensionsF;
ivec3 dimensions;
ivec3 blockDimensions;
uniform mat4 ndcToWorld;
uniform mat4 worldToNDC;
uniform mat4 worldToIJK;
uniform mat4 ijkToWorld;
uniform mat3 normalMatrix;
uniform vec2 viewportSize;
uniform float sampleDistance;
uniform float gradientStep;
uniform float ambientK;
uniform float diffuseK;
uniform float specularK;
uniform float specularPower;
uniform int anyIso;
uniform float minimumIso;
uniform int blendMode;
uniform float unitDistance;
uniform vec2 tableRange;
uniform int tableSize;
uniform int thinBone;
uniform float thinBoneThickness;
uniform int planeCount;
uniform vec4 planes[6];
uniform int refinements;

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

vec3 rayOrigin;     // IJK
vec3 rayDirection;  // IJK per mm
vec3 originWorld;
vec3 directionWorld;
vec4 accumulated = vec4(0.0);
bool firstHit = true;
float hitDepth = 1.0;
int layers = 0;

// ---- anatomy ---------------------------------------------------------------
void cellOf(vec3 p, out ivec3 base, out vec3 f)
{
  vec3 x = clamp(p, vec3(0.0), vec3(dimensions - 1));
  base = min(ivec3(x), dimensions - 2);
  f = x - vec3(base);
}

float intensity(vec3 p)
{
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  float v000 = texelFetch(anatomyTexture, b, 0).r;
  float v100 = texelFetch(anatomyTexture, b + ivec3(1, 0, 0), 0).r;
  float v010 = texelFetch(anatomyTexture, b + ivec3(0, 1, 0), 0).r;
  float v110 = texelFetch(anatomyTexture, b + ivec3(1, 1, 0), 0).r;
  float v001 = texelFetch(anatomyTexture, b + ivec3(0, 0, 1), 0).r;
  float v101 = texelFetch(anatomyTexture, b + ivec3(1, 0, 1), 0).r;
  float v011 = texelFetch(anatomyTexture, b + ivec3(0, 1, 1), 0).r;
  float v111 = texelFetch(anatomyTexture, b + ivec3(1, 1, 1), 0).r;
  float c00 = v000 + f.x * (v100 - v000);
  float c10 = v010 + f.x * (v110 - v010);
  float c01 = v001 + f.x * (v101 - v001);
  float c11 = v011 + f.x * (v111 - v011);
  float c0 = c00 + f.y * (c10 - c00);
  float c1 = c01 + f.y * (c11 - c01);
  return c0 + f.z * (c1 - c0);
}

vec4 styleColor(int label) { return texelFetch(styleTexture, ivec2(label, 0), 0); }
vec4 styleSurface(int label) { return texelFetch(styleTexture, ivec2(label, 1), 0); }

float cornerWeight(int corner, vec3 f)
{
  return ((corner & 1) != 0 ? f.x : 1.0 - f.x) * ((corner & 2) != 0 ? f.y : 1.0 - f.y) * ((corner & 4) != 0 ? f.z : 1.0 - f.z);
}

ivec3 cornerOffset(int corner) { return ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1); }

vec4 fractionsAt(vec3 p)
{
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  vec4 value = vec4(0.0);
  for (int corner = 0; corner < 8; ++corner)
  {
    value += cornerWeight(corner, f) * texelFetch(fractionTexture, b + cornerOffset(corner), 0);
  }
  return value;
}

int dominantLabel(vec3 p, out float weight)
{
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  int labels[12];
  float weights[12];
  int count = 0;
  float unlabelledBright = 0.0;
  for (int corner = 0; corner < 8 && hasLabelMap != 0; ++corner)
  {
    int label = int(texelFetch(labelTexture, b + cornerOffset(corner), 0).r + 0.5);
    float w = cornerWeight(corner, f);
    if (label == 0)
    {
      if (anyIso != 0 && texelFetch(anatomyTexture, b + cornerOffset(corner), 0).r >= minimumIso)
      {
        unlabelledBright += w;
      }
      continue;
    }
    int slot = 0;
    while (slot < count && labels[slot] != label)
    {
      ++slot;
    }
    if (slot == count)
    {
      labels[count] = label;
      weights[count] = 0.0;
      ++count;
    }
    weights[slot] += w;
  }
  if (fractionCount > 0)
  {
    vec4 fractions = fractionsAt(p);
    for (int i = 0; i < fractionCount; ++i)
    {
      int label = int(fractionLabels[i] + 0.5);
      int slot = 0;
      while (slot < count && labels[slot] != label)
      {
        ++slot;
      }
      if (slot == count)
      {
        labels[count] = label;
        ++count;
      }
      weights[slot] = fractions[i];
    }
  }
  int best = 0;
  weight = 0.0;
  for (int slot = 0; slot < count; ++slot)
  {
    if (weights[slot] > weight || (weights[slot] == weight && weight > 0.0 && labels[slot] < best))
    {
      best = labels[slot];
      weight = weights[slot];
    }
  }
  if (unlabelledBright > weight)
  {
    return 0;
  }
  return best;
}

float indicator(int label, vec3 p)
{
  for (int i = 0; i < fractionCount; ++i)
  {
    if (int(fractionLabels[i] + 0.5) == label)
    {
      return fractionsAt(p)[i];
    }
  }
  if (hasLabelMap == 0)
  {
    return 0.0;
  }
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  float value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    if (int(texelFetch(labelTexture, b + cornerOffset(corner), 0).r + 0.5) == label)
    {
      value += cornerWeight(corner, f);
    }
  }
  return value;
}

int objectAt(vec3 p, out float value)
{
  value = intensity(p);
  if (hasLabels == 0)
  {
    vec4 s = styleSurface(1);
    return (styleColor(1).a > 0.0 && value >= s.x) ? 1 : 0;
  }
  float weight;
  int label = dominantLabel(p, weight);
  if (label == 0 || label >= styleCount || styleColor(label).a <= 0.0)
  {
    return 0;
  }
  vec4 s = styleSurface(label);
  bool inside = s.y > 0.5 ? weight >= 0.5 : value >= s.x;
  return inside ? label : 0;
}

// ---- cut fields ----------------------------------------------------------------
//VolumeCut::CutDecl

Sample sampleAt(float t)
{
  Sample s;
  s.t = t;
  s.index = rayOrigin + t * rayDirection;
  s.object = 0;
  s.value = 0.0;
  s.cutsKnown = false;
  for (int n = 0; n < CUT_SLOTS; ++n)
  {
    s.distance[n] = 1.0;
  }
  return s;
}

void evaluateObject(inout Sample s) { s.object = objectAt(s.index, s.value); }

vec3 worldPoint(vec3 index) { return (ijkToWorld * vec4(index, 1.0)).xyz; }

float cutDistance(int n, vec3 world)
{
  //VolumeCut::CutCalls
  return 1.0;
}

void evaluateCuts(inout Sample s)
{
  if (s.cutsKnown)
  {
    return;
  }
  vec3 world = worldPoint(s.index);
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    s.distance[n] = cutDistance(n, world);
  }
  s.cutsKnown = true;
}

bool removed(Sample s)
{
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    if (s.distance[n] < 0.0)
    {
      return true;
    }
  }
  return false;
}

bool visible(inout Sample s)
{
  if (s.object == 0)
  {
    return false;
  }
  evaluateCuts(s);
  return !removed(s);
}

// ---- normals ---------------------------------------------------------------------
vec3 objectNormal(int object, vec3 p)
{
  vec3 gradient;
  bool shape = hasLabels != 0 && styleSurface(object).y > 0.5;
  for (int axis = 0; axis < 3; ++axis)
  {
    vec3 plus = p;
    vec3 minus = p;
    plus[axis] += gradientStep;
    minus[axis] -= gradientStep;
    gradient[axis] = shape ? indicator(object, plus) - indicator(object, minus) : intensity(plus) - intensity(minus);
  }
  return normalize(-(normalMatrix * gradient));
}

vec3 cutNormal(int n, vec3 world)
{
  float h = cutStepOf(n);
  vec3 normal;
  for (int axis = 0; axis < 3; ++axis)
  {
    vec3 plus = world;
    vec3 minus = world;
    plus[axis] += h;
    minus[axis] -= h;
    normal[axis] = cutDistance(n, minus) - cutDistance(n, plus);
  }
  return normalize(normal);
}

// ---- borders ---------------------------------------------------------------------
float bisectObject(Sample a, Sample b)
{
  float lo = a.t;
  float hi = b.t;
  for (int iteration = 0; iteration < 22; ++iteration)
  {
    Sample mid = sampleAt(0.5 * (lo + hi));
    evaluateObject(mid);
    if (mid.object == a.object)
    {
      lo = mid.t;
    }
    else
    {
      hi = mid.t;
    }
  }
  return 0.5 * (lo + hi);
}

float bisectCut(int n, Sample a, Sample b)
{
  float lo = a.t;
  float hi = b.t;
  bool loRemoved = a.distance[n] < 0.0;
  for (int iteration = 0; iteration < 22; ++iteration)
  {
    float t = 0.5 * (lo + hi);
    if ((cutDistance(n, worldPoint(rayOrigin + t * rayDirection)) < 0.0) == loRemoved)
    {
      lo = t;
    }
    else
    {
      hi = t;
    }
  }
  return 0.5 * (lo + hi);
}

ivec3 blockOf(vec3 p) { return clamp(ivec3(p) / BLOCK, ivec3(0), blockDimensions - 1); }

bool blockEmpty(vec3 p) { return texelFetch(blockTexture, blockOf(p), 0).r < 0.5; }

float blockExit(vec3 p, float t)
{
  float exitT = 1e30;
  ivec3 b = blockOf(p);
  for (int axis = 0; axis < 3; ++axis)
  {
    if (abs(rayDirection[axis]) < 1e-12)
    {
      continue;
    }
    float wall = rayDirection[axis] > 0.0 ? float((b[axis] + 1) * BLOCK) : float(b[axis] * BLOCK);
    exitT = min(exitT, t + (wall - p[axis]) / rayDirection[axis]);
  }
  return exitT;
}

bool mayHideBorders(Sample a, Sample b, float lengthVoxels, float lengthMillimetres)
{
  if (a.object == 0 && b.object == 0)
  {
    if (anyIso == 0)
    {
      return false;
    }
    float slope = max(texelFetch(blockTexture, blockOf(a.index), 0).g, texelFetch(blockTexture, blockOf(b.index), 0).g);
    return 0.5 * (a.value + b.value + slope * lengthVoxels) >= minimumIso;
  }
  if (!a.cutsKnown || !b.cutsKnown)
  {
    return false;
  }
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    float da = a.distance[n];
    float db = b.distance[n];
    if ((da >= 0.0) == (db >= 0.0) && abs(da) + abs(db) < lengthMillimetres)
    {
      return true;
    }
  }
  return false;
}

// ---- shading and compositing -------------------------------------------------------
vec3 shade(vec3 color, vec3 normal, vec3 view)
{
  float cosine = abs(dot(normal, view));
  float specular = specularK * pow(cosine, specularPower);
  return min(vec3(1.0), color * (ambientK + diffuseK * cosine) + vec3(specular));
}

void record(float t, vec3 rgb, float alpha, float minimumAlpha)
{
  float remaining = 1.0 - accumulated.a;
  accumulated.rgb += remaining * alpha * rgb;
  accumulated.a += remaining * alpha;
  if (firstHit && alpha >= minimumAlpha)
  {
    firstHit = false;
    vec4 clip = worldToNDC * vec4(originWorld + t * directionWorld, 1.0);
    hitDepth = clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);
  }
}

float measureThickness(int object, vec3 index, vec3 normalWorld)
{
  vec3 inwardIndex = mat3(worldToIJK) * (-normalWorld);
  float voxelsPerMillimetre = length(inwardIndex);
  if (voxelsPerMillimetre <= 0.0)
  {
    return thinBoneThickness;
  }
  float stepLength = 0.25 / voxelsPerMillimetre;
  for (float travelled = stepLength; travelled < thinBoneThickness; travelled += stepLength)
  {
    Sample s = sampleAt(0.0);
    s.index = index + travelled * inwardIndex;
    if (any(lessThan(s.index, vec3(0.0))) || any(greaterThan(s.index, vec3(dimensions - 1))))
    {
      return thinBoneThickness;
    }
    evaluateObject(s);
    if (!visible(s))
    {
      return travelled;
    }
  }
  return thinBoneThickness;
}

vec3 entryNormal;
vec3 viewVector;

bool enter(Sample piece, float t, int source)
{
  vec3 index = rayOrigin + t * rayDirection;
  vec3 normal;
  if (source == SOURCE_OBJECT)
  {
    normal = objectNormal(piece.object, index);
  }
  else if (source >= SOURCE_CUT)
  {
    normal = cutNormal(source - SOURCE_CUT, worldPoint(index));
  }
  else
  {
    normal = entryNormal;
  }
  if (dot(normal, viewVector) < 0.0)
  {
    normal = -normal;
  }
  vec4 style = styleColor(piece.object);
  vec3 rgb = shade(style.rgb, normal, viewVector);
  float alpha = style.a;
  if (thinBone != 0)
  {
    float thickness = measureThickness(piece.object, index, normal);
    if (thickness < thinBoneThickness)
    {
      float f = thickness / thinBoneThickness;
      rgb = mix(vec3(1.0, 0.12, 0.08), rgb, f);
      alpha *= 0.3 + 0.7 * f;
    }
  }
  record(t, rgb, alpha, 0.0);
  ++layers;
  return accumulated.a >= 0.995 || layers >= 8;
}

bool insideVisible = false;

// Insertion sort of at most NUMBER_OF_CUTS + 1 borders by ray parameter.
void sortBorders(inout float borderT[CUT_SLOTS + 1], inout int borderSource[CUT_SLOTS + 1], int count)
{
  for (int i = 1; i < count; ++i)
  {
    for (int j = i; j > 0 && borderT[j - 1] > borderT[j]; --j)
    {
      float t = borderT[j];
      borderT[j] = borderT[j - 1];
      borderT[j - 1] = t;
      int source = borderSource[j];
      borderSource[j] = borderSource[j - 1];
      borderSource[j - 1] = source;
    }
  }
}

// The borders between two samples and the first visible piece between them.
bool leafInterval(inout Sample a, inout Sample b)
{
  float borderT[CUT_SLOTS + 1];
  int borderSource[CUT_SLOTS + 1];
  int count = 0;
  if (a.object != b.object)
  {
    borderT[count] = bisectObject(a, b);
    borderSource[count] = SOURCE_OBJECT;
    ++count;
  }
  if (a.cutsKnown && b.cutsKnown)
  {
    for (int n = 0; n < NUMBER_OF_CUTS; ++n)
    {
      if ((a.distance[n] < 0.0) != (b.distance[n] < 0.0))
      {
        borderT[count] = bisectCut(n, a, b);
        borderSource[count] = SOURCE_CUT + n;
        ++count;
      }
    }
  }
  sortBorders(borderT, borderSource, count);
  for (int border = 0; border < count; ++border)
  {
    float endT = border + 1 < count ? borderT[border + 1] : b.t;
    Sample mid = sampleAt(0.5 * (borderT[border] + endT));
    evaluateObject(mid);
    bool isVisible = visible(mid);
    if (isVisible && !insideVisible && enter(mid, borderT[border], borderSource[border]))
    {
      return true;
    }
    insideVisible = isVisible;
  }
  return false;
}

bool surfaceInterval(inout Sample a, inout Sample b, float voxelsPerMillimetre)
{
  if (a.object != 0 || b.object != 0)
  {
    evaluateCuts(a);
    evaluateCuts(b);
  }
  if (mayHideBorders(a, b, (b.t - a.t) * voxelsPerMillimetre, b.t - a.t))
  {
    int parts = 1 << refinements;
    Sample from = a;
    for (int part = 1; part <= parts; ++part)
    {
      Sample to = part == parts ? b : sampleAt(a.t + (b.t - a.t) * float(part) / float(parts));
      if (part < parts)
      {
        evaluateObject(to);
      }
      if (from.object != 0 || to.object != 0)
      {
        evaluateCuts(from);
        evaluateCuts(to);
      }
      if (leafInterval(from, to))
      {
        return true;
      }
      from = to;
    }
    return false;
  }
  return leafInterval(a, b);
}

vec4 lookUp(float value)
{
  float span = tableRange.y - tableRange.x;
  float x = span > 0.0 ? (value - tableRange.x) / span * float(tableSize - 1) : 0.0;
  x = clamp(x, 0.0, float(tableSize - 1));
  int i = min(int(x), tableSize - 2);
  float f = x - float(i);
  return mix(texelFetch(transferTexture, ivec2(i, 0), 0), texelFetch(transferTexture, ivec2(i + 1, 0), 0), f);
}

void main()
{
  dimensions = ivec3(dimensionsF + 0.5);
  blockDimensions = ivec3(blockDimensionsF + 0.5);
  //VolumeCut::CutInit
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
  for (int axis = 0; axis < 3; ++axis)
  {
    float lo = 0.0;
    float hi = float(dimensions[axis] - 1);
    if (abs(rayDirection[axis]) < 1e-15)
    {
      if (rayOrigin[axis] < lo || rayOrigin[axis] > hi)
      {
        discard;
      }
      continue;
    }
    float t0 = (lo - rayOrigin[axis]) / rayDirection[axis];
    float t1 = (hi - rayOrigin[axis]) / rayDirection[axis];
    bool forward = t0 < t1;
    if (!forward)
    {
      float swap = t0;
      t0 = t1;
      t1 = swap;
    }
    if (t0 > tStart)
    {
      tStart = t0;
      vec3 face = vec3(0.0);
      face[axis] = forward ? -1.0 : 1.0;
      entryNormal = normalize(normalMatrix * face);
    }
    tEnd = min(tEnd, t1);
  }
  for (int p = 0; p < planeCount; ++p)
  {
    float f0 = dot(planes[p].xyz, originWorld) + planes[p].w;
    float fd = dot(planes[p].xyz, directionWorld);
    if (abs(fd) < 1e-15)
    {
      if (f0 < 0.0)
      {
        discard;
      }
      continue;
    }
    float t = -f0 / fd;
    if (fd > 0.0)
    {
      if (t > tStart)
      {
        tStart = t;
        entryNormal = -normalize(planes[p].xyz);
      }
    }
    else
    {
      tEnd = min(tEnd, t);
    }
  }
  if (!(tStart < tEnd))
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
    Sample b = sampleAt(min(a.t + stepLength, tEnd));
    evaluateObject(b);
    if (!composite)
    {
      done = surfaceInterval(a, b, voxelsPerMillimetre);
      a = b;
      continue;
    }
    evaluateCuts(a);
    evaluateCuts(b);
    float borderT[CUT_SLOTS + 1];
    int borderCut[CUT_SLOTS + 1];
    int count = 0;
    for (int n = 0; n < NUMBER_OF_CUTS; ++n)
    {
      if ((a.distance[n] < 0.0) != (b.distance[n] < 0.0))
      {
        borderT[count] = bisectCut(n, a, b);
        borderCut[count] = n;
        ++count;
      }
    }
    sortBorders(borderT, borderCut, count);
    float startT = a.t;
    for (int piece = 0; piece <= count && !done; ++piece)
    {
      float endT = piece < count ? borderT[piece] : b.t;
      if (endT > startT)
      {
        Sample mid = sampleAt(0.5 * (startT + endT));
        evaluateObject(mid);
        evaluateCuts(mid);
        if (!removed(mid))
        {
          vec4 tf = lookUp(mid.value);
          if (tf.a > 0.0)
          {
            float alpha = 1.0 - pow(1.0 - min(tf.a, 0.9999), (endT - startT) / unitDistance);
            vec3 normal;
            if (lastCutBorder >= 0)
            {
              normal = cutNormal(lastCutBorder, worldPoint(mid.index));
            }
            else
            {
              vec3 gradient;
              for (int axis = 0; axis < 3; ++axis)
              {
                vec3 plus = mid.index;
                vec3 minus = mid.index;
                plus[axis] += gradientStep;
                minus[axis] -= gradientStep;
                gradient[axis] = intensity(minus) - intensity(plus);
              }
              normal = normalize(normalMatrix * gradient);
            }
            record(startT, shade(tf.rgb, normal, viewVector), alpha, 0.02);
            done = accumulated.a >= 0.995;
          }
          lastCutBorder = -1;
        }
      }
      if (piece < count)
      {
        lastCutBorder = borderCut[piece];
      }
      startT = endT;
    }
    a = b;
  }
  if (accumulated.a <= 0.0)
  {
    discard;
  }
  gl_FragData[0] = accumulated;
  gl_FragDepth = hitDepth;
}
