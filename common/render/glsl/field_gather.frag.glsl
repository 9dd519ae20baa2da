// Every colour field of a frame from one render (Lancelle, Voß & Fellner, "Fast
// Motion Rendering for Single-Chip Stereo DLP Projectors"): a field shows the
// scene `shift` frame periods after the rendered moment, when the surface drawn
// at y is at y + v(y)·shift. For each pixel x and field, candidates y are taken
// along the fastest velocity near x (the neighbour max of McGuire et al.); the
// front-most candidate whose motion lands on x gives the surface, read at
// x − v·shift between the texels of that surface, over what lies behind it.
// Where none lands on x, the surface there was hidden in the render
// (disocclusion): the farthest candidate fills it.
// Faster than the threshold, the eye is taken not to follow: the pixel gets the
// average over the frame's moments (motion blur), the same in every channel.
// Without fields (drawn per field elsewhere), only that blur and its weight, to
// be blended over them.
// Built with "#version 450 core" first.
const int kMaxFields = 3;
layout(binding = 0) uniform sampler2D colour;
layout(binding = 1) uniform sampler2D motion;  // velocity (pixels per frame, rows up), linear depth
layout(binding = 2) uniform sampler2D neighbour_max;
uniform int tile;
uniform int field_count;
uniform vec3 field_channels[kMaxFields];
uniform float field_shift[kMaxFields];
uniform int samples;     // candidates per field, ≥ 2
uniform float radius;    // the farthest a field moves a surface, pixels
uniform vec2 blur_band;  // pixels per frame: fields below, blur above, a mix between; 0, 0: no blur
uniform vec2 frame_shift;  // the frame's first and last moment, as shifts
layout(location = 0) out vec4 result;

vec2 displacement(vec2 v, float shift) {
  vec2 d = v * shift;
  float l = length(d);
  return l > radius ? d * (radius / l) : d;
}

// Whether a surface moving at `d` this field is the one moving at `layer`.
bool same_layer(vec2 d, vec2 layer) {
  vec2 apart = abs(d - layer);
  return max(apart.x, apart.y) < 0.5;
}

vec3 at_moment(vec2 x, vec2 fastest, float shift, vec2 size) {
  vec2 reach = displacement(fastest, shift);
  float span = length(reach);
  if (span < 1e-3) return texelFetch(colour, ivec2(x), 0).rgb;
  float spacing = span / float(samples - 1);
  // A candidate's texel lands near x when it is within the reach of a bilinear
  // weight; sparse candidates are given half their spacing more.
  float tolerance = 0.5 + 0.5 * max(spacing - 1.0, 0.0);
  float nearest = 3.0e38;
  vec2 front = vec2(0.0);
  bool found = false;
  float farthest = -1.0;
  ivec2 behind = ivec2(x);
  ivec2 last = ivec2(size) - 1;
  for (int j = 0; j < samples; ++j) {
    vec2 y = x - reach * (float(j) / float(samples - 1));
    ivec2 c = clamp(ivec2(floor(y)), ivec2(0), last);
    vec4 m = texelFetch(motion, c, 0);
    vec2 d = displacement(m.xy, shift);
    vec2 miss = abs(vec2(c) + 0.5 + d - x);
    if (max(miss.x, miss.y) < tolerance && m.z < nearest) {
      nearest = m.z;
      front = d;
      found = true;
    }
    if (m.z > farthest) {
      farthest = m.z;
      behind = c;
    }
  }
  // What lies behind the front surface: x's own texel if it stays (it was not
  // covered), else the farthest candidate — the background stretched over what
  // the render did not see.
  vec4 own = texelFetch(motion, ivec2(x), 0);
  vec3 back = all(lessThan(abs(displacement(own.xy, shift)), vec2(0.5))) ? texelFetch(colour, ivec2(x), 0).rgb
                                                                         : texelFetch(colour, behind, 0).rgb;
  if (!found) return back;
  // The front surface where it was: over the four texels around its source,
  // each of another surface giving its weight to the one behind. The weights
  // are bilinear made steeper (smoothstep): a plain bilinear read blurs the
  // render's edges over two pixels (measured: 0.3 dB less against the per-field
  // image at 6 px per frame).
  vec2 source = x - front - 0.5;
  ivec2 base = ivec2(floor(source));
  vec2 f = smoothstep(0.0, 1.0, source - vec2(base));
  vec3 sum = vec3(0.0);
  float covered = 0.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    ivec2 t = clamp(base + o, ivec2(0), last);
    float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    if (w <= 0.0 || !same_layer(displacement(texelFetch(motion, t, 0).xy, shift), front)) continue;
    sum += w * texelFetch(colour, t, 0).rgb;
    covered += w;
  }
  return sum + (1.0 - covered) * back;
}

void main() {
  vec2 size = vec2(textureSize(colour, 0));
  vec2 x = gl_FragCoord.xy;
  vec2 fastest = texelFetch(neighbour_max, ivec2(x) / tile, 0).xy;
  vec3 shown = vec3(0.0);
  for (int f = 0; f < field_count; ++f) shown += field_channels[f] * at_moment(x, fastest, field_shift[f], size);
  // A band around the threshold, not a step: a speed that wavers across it does
  // not make the image jump between fields and blur from frame to frame.
  float blur = blur_band.y > 0.0 ? smoothstep(blur_band.x, blur_band.y, length(fastest)) : 0.0;
  vec3 blurred = vec3(0.0);
  if (blur > 0.0) {
    for (int k = 0; k < samples; ++k) {
      float u = mix(frame_shift.x, frame_shift.y, (float(k) + 0.5) / float(samples));
      blurred += at_moment(x, fastest, u, size);
    }
    blurred /= float(samples);
  }
  result = field_count == 0 ? vec4(blurred, blur) : vec4(mix(shown, blurred, blur), 1.0);
}
