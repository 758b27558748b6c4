# Scene files shared by scripts/reference-validation.sh and scripts/transmittance-calibration.sh (sourced, not run):
# every key written out, so that their figures do not follow later changes of the built-in scenes' defaults.
# The caller sets `size` (pixels, square) and `samples` (path-traced samples per pixel).

# Settings shared by every scene: the SSS width, and the path tracer set to agree with the rasterizer everywhere
# but in the subsurface transport: no interreflection, a hard sun, pixel-centre sampling, and the rasterizer's
# specular layer, Lambertian diffuse (docs/pathtraced.md, "Rasterizer and Cycles"), and the random-walk radius
# following the albedo per texel (docs/pathtraced.md, "Matched profiles").
common_tail() {
  cat <<EOF

[render]
width = $size
height = $size
exposure_ev = 0.0
antialiasing = "none"

[tone_map]
operator = "filmic"

[sss]
width_mm = 3.0
$(if [ -n "${SKIN_TONE:-}" ]; then printf '\n[skin]\ntone = "%s"\n' "$SKIN_TONE"; fi)

[pathtraced]
samples = $samples
max_bounces = 0
sun_angle_deg = 0.0
filter_width_px = 0.01
specular_source = "rasterizer"
environment_shadow = false
radius_model = "albedo"
diffuse = "lambert"
EOF
}

# builtin:ear: a skin fin THICKNESS_MM thick, lit from behind (through-light) and weakly from the front; with
# SIDE = front the key light comes from the camera's side instead (no through-light to see).
ear_scene() {  # ear_scene THICKNESS_MM [SIDE: back (default) | front]
  local key_z=0.97
  case "${2:-back}" in back) ;; front) key_z=-0.97 ;; *) echo "ear_scene: side '$2' is neither back nor front" >&2; return 2 ;; esac
  cat <<EOF
mm_per_unit = 1.0

[model]
source = "builtin:ear"
thickness_mm = $1

[[materials]]
name = "skin"
albedo = [0.60, 0.42, 0.34]
skin = true
glossiness = 0.6
specular_intensity = 1.0

[camera]
view = "mid"
fov_deg = 30.0
yaw_deg = 0.0
pitch_deg = 0.0

[[lights]]
type = "directional"
direction = [0.15, -0.2, $key_z]
color = [1.0, 0.95, 0.88]
intensity = 3.0
shadow = true

[[lights]]
type = "directional"
direction = [-0.3, -0.3, -0.9]
color = [1.0, 1.0, 1.0]
intensity = 0.15
shadow = false

[environment]
radiance = [0.03, 0.03, 0.035]
intensity = 1.0
background = "color"
background_color = [0.01, 0.01, 0.01]
EOF
  common_tail
}
