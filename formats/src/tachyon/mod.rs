//! # Tachyon scenes (`.dat`): Tachyon 0.99b6's scene language and VMD's exports
//!
//! [`load`] reads a Tachyon scene into a [`SceneDesc`]; [`parse_file`] gives the syntax tree
//! (module [`syntax`]) with every statement and option as written and where. The grammar is
//! the one `tachyon-nox` 0.99b6 (Debian) accepts, measured statement by statement; what each
//! statement means in Luxon is below. Measurements and their scripts:
//! `/work/notes/tachyon-mapping.md` and `/work/notes/tachyon-measure/`.
//!
//! ## Reading
//!
//! - Words are separated by whitespace; keywords are matched in any case (`Sphere`, `SPHERE`),
//!   names and paths keep theirs (`TEXDEF red` is not `RED`). `#` starts a comment only as a
//!   word of its own where a statement may start (`#comment` is an error, as in Tachyon).
//! - Numbers are C's `%f`; fields Tachyon reads with `%d` (RESOLUTION, ANTIALIASING, RAYDEPTH,
//!   TEXFUNC, counts, indices, DIM, RES, SAMPLES...) must be whole numbers: `RESOLUTION 4.0 4`
//!   is "expected a whole number" at the `4.0` (Tachyon itself misreads it). NaN and
//!   infinities are refused.
//! - The file must start with `BEGIN_SCENE` (after comments) and `RESOLUTION x y`; `.dat` is a
//!   generic extension, so a file that does not is reported as "expected `BEGIN_SCENE`".
//!   `END_SCENE` ends the scene (the rest of the file is not read); a file may also just end.
//! - Statements keep Tachyon's fixed word order and its optional parts in Tachyon's order.
//!   Every error names `file:line:col`, what was expected (with the statement's form) and
//!   what was found. Tachyon reads on after many of these mistakes and renders something
//!   else, or exits with status 0 and no image; Luxon stops and says where.
//! - `INCLUDE file` reads the file's statements in place (its `END_SCENE` ends only that
//!   file); cycles and more than 32 levels are errors.
//! - Relative paths (INCLUDE, image maps, volumes, `.tpoly` files) are looked up in the working
//!   directory first, as Tachyon does, then beside the file that names them; an error or
//!   warning names both places.
//! - VMD's `PERSPECTIVE_DOF FOCALDIST f APERTURE a` is accepted beside Tachyon 0.99b6's
//!   `FOCALLENGTH` (which 0.99b6 requires).
//!
//! Where Tachyon's leniency is part of what real files show, Luxon does the same and adds a
//! warning (`SceneDesc::warnings`, printed by the command line): an undefined texture name
//! (Tachyon's default texture: AMBIENT 0.1, DIFFUSE 0.9, white), a missing image map or
//! undefined IMAGEDEF (white: Tachyon's message says "solid gray", its picture is white), a
//! missing volume file (the volume's box in its texture's
//! colour, unlit), a second TEXDEF of a name (the first stays). Features Luxon does not render as
//! Tachyon does yet are one warning each, at their first use (see "Not yet" below).
//!
//! ## Coordinates
//!
//! Tachyon's world is left-handed: with VIEWDIR +z and UPDIR +y, +x is on the right (screen
//! right = UPDIR × VIEWDIR). Luxon's camera is right-handed (right = forward × up). The
//! importer mirrors the world: every point, direction and plane has its z negated (camera,
//! lights, geometry, normals, clip planes, texture centres and axes, volume grids). The picture
//! is then Tachyon's, and the imported scene is an ordinary Luxon scene. Mirroring reverses
//! triangle windings, so each triangle's second and third vertices (and normals) swap, keeping
//! vertex normals on the same side of the winding as in the file.
//!
//! ## Camera and image
//!
//! | Tachyon | Luxon |
//! |---|---|
//! | `RESOLUTION x y` | `render.width`, `height` |
//! | `CENTER`, `VIEWDIR`, `UPDIR` | `position`, `look_at = position + VIEWDIR`, `up` (mirrored) |
//! | `ZOOM z`, `ASPECTRATIO a` | a window `1/z` high and `(x/y)/(a·z)` wide at unit distance (perspective) or in world units (orthographic), given as a `frustum` |
//! | `FRUSTUM l r b t` | that window instead (Tachyon's order: left right bottom top) |
//! | pixel sampling | Tachyon samples pixel (i, j) at ((i+1)/x, (j+1)/y) of the window, half a pixel right of and above the centre Luxon samples: the window is moved by half a pixel right and up |
//! | `ANTIALIASING n` | `samples: n + 1` with `centre_sample` (Tachyon: one sample at the pixel's centre plus n anywhere in it; the noise differs) |
//! | `RAYDEPTH n` | `max_depth: n - 1` (Tachyon's primary ray counts as one level) |
//! | `PROJECTION ORTHOGRAPHIC` | `Orthographic` with the same window |
//! | `PROJECTION FISHEYE` | not a circular fisheye: Tachyon's window (zoom, aspect or FRUSTUM) in radians of longitude and latitude around VIEWDIR, so `Equirectangular` with that `frustum` in degrees, half a pixel moved like the others |
//! | `PERSPECTIVE_DOF FOCALLENGTH f APERTURE a` | Tachyon 0.99b6 ignores f and focuses at unit distance; its lens is a rectangle a × the window: a disc of the same area, radius `a·√(w·h/π)`, focused at distance 1; no lens without ANTIALIASING (Tachyon traces only the pinhole ray then) |
//! | `... FOCALDIST f APERTURE a` (VMD) | the same lens, focused at distance f |
//! | no CAMERA | zoom 1, aspect 1, no antialiasing, ray depth 6, at the origin looking along +z |
//!
//! The last CAMERA, BACKGROUND and FOG of the file win.
//!
//! ## Colours
//!
//! Tachyon's colours are display values: it shades with them as written and writes the result
//! clamped, without gamma. They are imported as written (no sRGB-to-linear conversion as the
//! NFF importer does), because Tachyon's arithmetic (ambient + diffuse sums, products of
//! light and surface colours, mirror and transmission mixes) is on these values: converting
//! would change every mix, and only an output written without sRGB encoding can show
//! Tachyon's tones: `luxon tachyon` writes its images so (the writers' `encoding: display`:
//! values as they are, clamped and truncated as Tachyon writes them). `luxon render` writes
//! sRGB unless an output asks for `encoding: display`, so there midtones come out brighter
//! than Tachyon's; where both are 0 or 1 they agree.
//!
//! ## Lights, shading settings, fog
//!
//! | Tachyon | Luxon |
//! |---|---|
//! | `LIGHT CENTER RAD COLOR` | `Point` light of that colour, intensity 1, with shadows; with RAD > 0 also a sphere of that radius in the light's colour, unlit (`ambient: 1`, `diffuse: 0`), unfogged (`fog: false`) and casting no shadow (`InlineGeometry::shadowless`), as Tachyon draws it |
//! | `ATTENUATION CONSTANT c LINEAR l QUADRATIC q` | `attenuation: (c, l, q)`, the same 1/(c + l·d + q·d²) (on diffuse light only: see `plain_highlights` below) |
//! | `DIRECTIONAL_LIGHT DIRECTION d COLOR c` | `Directional` travelling along d |
//! | `SPOTLIGHT ... FALLOFF_START s FALLOFF_END e` | `Spot` with `angle: 2e`, `falloff: 2(e − s)`, `fade: Linear`: full inside s, none beyond e, linear in the angle between (Tachyon's ramp); RAD > 0 draws a sphere as LIGHT does |
//! | `SKY_LIGHT NUMSAMPLES n COLOR c` | `ambient_occlusion`: n samples, unlimited distance, colour c, direct 1 |
//! | `SHADER_MODE ... AMBIENT_OCCLUSION AMBIENT_COLOR c RESCALE_DIRECT r SAMPLES n` | the same with `direct: r`; r scales direct light even where occlusion is off (MEDIUM shading, measured), there as every light's `intensity` |
//! | `SHADER_MODE FULL` / `MEDIUM` | everything / no shadows and no occlusion |
//! | `SHADER_MODE LOW` / `LOWEST` | every surface shows its texture colour unlit (no fog) / white on black |
//! | (default), `TRANS_ORIG` | `transparency: (mode: Additive)`: the surface shaded as if opaque plus (1 − o)·behind, untinted |
//! | `TRANS_VMD` | `mode: PostMultiplied, scale_reflection: true`: o·(shading and mirror reflection) + (1 − o)·behind |
//! | `TRANS_RASTER3D` (with either), texture `TRANSMODE R3D` | `angle: Raster3D` (render) / `transparency_angle: Raster3D` (material): opacity o seen along D becomes ¼(1 + cos(π(1 − o)(N·D)))² |
//! | `TRANS_MAX_SURFACES n` | `max_surfaces: n, beyond_max: Skip`: later transparent surfaces are not drawn at all |
//! | shadows through transparent surfaces, `SHADOW_FILTER_OFF` | `shadows: Untinted` (× (1 − o) per crossing, grey) / `shadows: Off` (none) |
//! | `FOG LINEAR START s END e` | `Linear { start, end }` |
//! | `FOG EXP` / `EXP2 START s DENSITY d` | `Exp` / `Exp2 { density, start }` (a negative START is taken as 0, with a warning) |
//! | fog (any mode) | `every_ray: true` (every ray fogged over its own segment, reflections and transmissions included, as Tachyon shades), `misses: true` (rays that miss show the fog colour) |
//! | `FOG_VMD` | `planar: true` (camera rays' depth along the view direction), `misses: false` (the background stays) |
//! | `BACKGROUND c` | `background: (r, g, b)` |
//! | `BACKGROUND_GRADIENT SKY_SPHERE UPDIR u TOPVAL t BOTTOMVAL b TOPCOLOR ct BOTTOMCOLOR cb` | `background: Gradient(kind: Sphere, up: u, top: t, bottom: b, top_color: ct, bottom_color: cb)`, u mirrored and not normalised (Tachyon's isn't): a missed ray of direction D shows the mix s·ct + (1 − s)·cb, s = (u·D − b) / (t − b) clamped to 0..1 |
//! | `... SKY_ORTHO_PLANE ...` | `kind: OrthoPlane`: s from u·O, O where the ray starts (an orthographic camera's rays start across its window: the gradient sweeps the picture; a perspective camera's all start at CENTER: one colour; a reflected ray starts at its mirror) |
//!
//! Tachyon evaluates its background for every ray that misses (camera, reflected and
//! transmitted rays alike) and, past the ray depth, for the ray that reached the last surface
//! (the mirror shows the background of the incident ray, not of the reflection), and so does
//! Luxon (`depth_limit_background`). Radial fog turns every miss into the fog colour, so no
//! gradient is seen; with FOG_VMD misses keep the gradient (and reflected rays' fog applies over
//! their segments as for hits). Once a BACKGROUND_GRADIENT is given it is shown, whatever
//! BACKGROUND says before or after it (measured); the last one wins. TOPVAL = BOTTOMVAL is a
//! sharp horizon; UPDIR 0 0 0 gives every ray the same mix, a plain colour. `SHADER_MODE
//! LOWEST` shows black instead.
//!
//! Three rules of Tachyon's shading are render settings the importer turns on
//! (`render.tachyon`): a light counts only where its term N·L × attenuation × spot fade ×
//! rescale exceeds 1/510 (`light_threshold`, with mirror and transmission coefficients of
//! 1/510 or less ignored); highlights take the light's whole colour, without attenuation, spot
//! fade or transparent-shadow filtering, and METAL's the surface colour in its place
//! (`plain_highlights`); a ray past the depth limit adds the background unscaled
//! (`depth_limit_background`).
//!
//! ## Command-line options
//!
//! [`load_with`] takes [`Options`], Tachyon's command-line overrides (`luxon tachyon` fills
//! them). They replace the scene's settings after the whole file is read, as Tachyon applies
//! them, and then map like the statements they stand for (`-mediumshade` as `SHADER_MODE
//! MEDIUM`, `-trans_vmd` as `TRANS_VMD`, `-aasamples n` as `ANTIALIASING n`, `-res` as
//! `RESOLUTION`), with the same warnings, placed at the command line. Tachyon keeps one direct
//! light scale: RESCALE_DIRECT sets it, `-rescale_lights f` replaces it when f < 1 (Tachyon
//! ignores larger factors), `-auto_skylight f` sets it to 1 − f and turns on occlusion of
//! colour f (`-add_skylight f`: occlusion only), with `-skylight_samples` rays (128 by
//! default). `-shade_phong` gives every material Phong highlights, `-shade_nullphong` none;
//! `-shade_blinn_fast` Tachyon's fast Blinn (`highlight: BlinnFast`).
//!
//! ## Textures and materials
//!
//! A texture body `AMBIENT a DIFFUSE d SPECULAR s OPACITY o [PHONG kind p PHONG_SIZE n] COLOR c
//! TEXFUNC ...` becomes a material: `color: c`, `ambient: a` (Tachyon's ambient term has no
//! light colour: nor has Luxon's), `diffuse: d`, `reflect: s` (Tachyon's SPECULAR is the mirror
//! reflectance, without Fresnel in both), `specular: p`, `shininess: n`, `highlight: Blinn`
//! (Tachyon's default), `highlight_color: Light` for PLASTIC (and any other word) or `Surface`
//! for METAL, `transmit: 1 − o` without refraction (`ior: 1`), `TRANSMODE R3D` as
//! `transparency_angle: Raster3D`, `OUTLINE o OUTLINE_WIDTH w` as `outline: o, outline_width: w`
//! (the diffuse light, lights and occlusion, times (1 − o) + o·(1 − (1 − (N·D)²)^(32(1 − w))),
//! Tachyon's formula; values outside 0..1 are clamped with a warning). `TEXDEF name` gives
//! the material that name; `TEXALIAS` another name for it; inline bodies become `tachyon-N`,
//! shared by every body that maps to the same material.
//!
//! | TEXFUNC | Luxon |
//! |---|---|
//! | 0 (and any number without a meaning) | the colour |
//! | 1 checker | the `checker` texture, exactly Tachyon's: cells ⅓ wide with boundaries ⅙ from CENTER, odd cells (1, 0.2, 0), even (0, 0.2, 1); COLOR, ROTATE, SCALE ignored as in Tachyon |
//! | 2 grit | the `noise` texture from 0.8·COLOR to COLOR, fine-grained (Tachyon draws a new random factor at every lookup) |
//! | 3 marble | the `tachyon_marble` texture: Tachyon's formula and its value noise (the same lattice from the same random sequence, integer interpolation), so the same veins; CENTER, ROTATE, SCALE and COLOR are ignored, as in Tachyon. Measured: within a few codes of Tachyon's pixels, which read the hit point in single precision, except on the pattern's jumps |
//! | 4 wood | the `tachyon_wood` texture: Tachyon's rings about the y axis through CENTER, the point divided by SCALE per axis, (0.8, 1, 0.2) and black; CENTER mirrored and SCALE.z negated, so the texture sees Tachyon's coordinates (the rings' wave is not symmetric in z); ROTATE and COLOR ignored, as in Tachyon; a SCALE with a 0 (Tachyon divides by it) shows COLOR, with a warning |
//! | 5 gradient noise | the colour (Tachyon's noise value is clamped to 1 almost everywhere) |
//! | 6 cylindrical checker | the `tachyon_cylinder_checker` texture: 18 sectors about the z axis through CENTER (the angle from +x toward +y) by bands 0.1 high along it, counted from CENTER by \|height\|, odd cells (1, 0.2, 0), even (0, 0.2, 1); CENTER mirrored; ROTATE, SCALE and COLOR ignored, as in Tachyon |
//! | 10 volume image | the `tachyon_volume_image` texture with the IMAGEDEF's texels: u = UAXIS·(p − CENTER)·SCALE.x + ROTATE.x, likewise v (VAXIS, y) and w (WAXIS, z), wrapped into [0, 1), trilinear with the first and last texels' centres at 0 and 1 (measured against `tachyon-nox`: within 2 codes); CENTER and the axes mirrored; an undefined IMAGEDEF is white with a warning, as in Tachyon; blocks over a million texels show COLOR with a note |
//! | 7, 8, 9 image maps | the `image` texture (`srgb: false`: texels are display values like colours), mappings `cylindrical`, `spherical` (both about +y, longitude from +x toward Tachyon's +z, as Tachyon's) and `planar` (axis UAXIS × VAXIS, turned and scaled so that u = UAXIS·(p − CENTER)·SCALE.x + ROTATE.x); v runs from the image's first row in memory (PPM: the top row, so it is flipped; TGA: the bottom row); a negative SCALE mirrors; `filter: tachyon(k)`, k = 0.05 × the larger \|SCALE\|: Tachyon's MIP blur, which grows with the distance the ray travelled from the camera (through mirrors and glass), not with the pixel's footprint, divided by 8 × the point's distance from CENTER for cylindrical and spherical maps |
//!
//! ## Geometry
//!
//! | Tachyon | Luxon |
//! |---|---|
//! | `SPHERE` | inline sphere |
//! | `TRI`, `STRI` | inline triangles (flat; with vertex normals); triangles without area are left out, as Tachyon does; smooth ones shadow themselves at the terminator as their flat facets do (`terminator_shadows`, as Tachyon's shadow rays start on the facet) |
//! | `VCSTRI ... C0 C1 C2 surface VCST` | an inline triangle with vertex normals and vertex `colors`, in the surface's material in white: the colours interpolated barycentrically are the surface colour, lit as any other (ambient, diffuse, highlights, mirror, transparency; METAL highlights take the vertex colour), as Tachyon does (measured) |
//! | `FCYLINDER BASE APEX RAD` | inline open cylinder (a cone with equal radii) |
//! | `POLYCYLINDER` | a sphere at every point and an open cylinder between neighbours (as Tachyon builds it) |
//! | `RING` | inline disc with a hole |
//! | `PLANE` | inline plane |
//! | `BOX` | the `box` plugin |
//! | `CYLINDER` (infinite) | the `infinite_cylinder` plugin |
//! | `VERTEXARRAY` with `TRIMESH` / `TRISTRIP` | inline meshes with vertex normals, each in the TEXTURE before it (Tachyon's default texture before the first); strips alternate their first two indices |
//! | `VERTEXARRAY ... COLORS` | the meshes after it take those vertex `colors`, interpolated as VCSTRI's, in their TEXTURE's material in white and without its TEXFUNC: Tachyon's vertex colours replace the texture's colour and pattern (measured) |
//! | `SCAPE` | Tachyon's terrain generator reproduced (its random sequence and midpoint subdivision), an inline mesh with its normals |
//! | `TPOLYFILE` | the `.tpoly` file's triangles through Tachyon's SCALE/ROT/CENTER transform (its "rotation" matrix included, which mirrors when ROT.y ≠ 0), as TRI (v1, v0, v2) |
//! | `SCALARVOL` | a `raw` u8 volume, voxel 0 at MIN and the last at MAX, nearest-voxel samples every \|MAX − MIN\| / \|DIM\|, emitting Tachyon's red-yellow-white ramp with opacity OPACITY·s / \|MAX − MIN\| per unit length (s the voxel / 255), composited as Tachyon's (`additive_volumes`: opacities summed without attenuation up to 1, the box counted twice); a file with extra whole slices is read and cropped to the box (Tachyon reads the first DIM voxels) |
//! | `START_CLIPGROUP NUMPLANES n a b c d ...` | clip group `clip-N` of planes with normal (a, b, c) through d·(a, b, c)/\|(a, b, c)\|² cutting away a·x + b·y + c·z > d, on every object up to END_CLIPGROUP (a new group replaces the one in effect) |
//!
//! ## Not yet
//!
//! Read into the syntax tree and reported with one warning each, but not rendered as Tachyon
//! renders them: image maps whose placement the image texture cannot express (skewed planar
//! axes, a SCALE that mirrors); a SCALARVOL's box as a shadow caster. Also different in
//! small ways: the lens shape of PERSPECTIVE_DOF (a disc, Tachyon's is a rectangle: wider
//! windows blur more sideways in Tachyon), the coarse MIP levels of an image map (Tachyon
//! averages 2 × 2 bytes and drops an odd last row or column; Luxon's levels are exact area
//! averages), and the noise of antialiasing, depth of field and occlusion.

mod files;
mod lex;
mod map;
mod materials;
mod notes;
mod options;
mod parse;
mod ron;
mod shapes;
pub mod syntax;
mod terrain;

use std::path::Path;

use crate::desc::SceneDesc;
use crate::error::SceneError;
use crate::origin::{Origin, Spanned};

pub use options::{Highlights, Options, Skylight};
pub use syntax::ShadeLevel;

/// Problems that did not stop the import, each where it was found.
type Warnings = Vec<Spanned<String>>;

/// Tachyon's world to Luxon's: z negated (see "Coordinates").
fn mirror(v: [f64; 3]) -> [f64; 3] {
    [v[0], v[1], -v[2]]
}

/// True for names ending in `.dat` (any case).
pub fn is_tachyon_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("dat"))
}

/// Reads a Tachyon scene file (and its INCLUDEs, `.tpoly` files) into its syntax tree.
pub fn parse_file(path: &Path) -> Result<syntax::Scene, SceneError> {
    parse::parse_file(path, options::MAX_TEXT)
}

/// Loads a Tachyon scene file as a Luxon scene (no outputs: the command line gives them).
pub fn load(path: &Path) -> Result<SceneDesc, SceneError> {
    let at = Origin {
        file: std::sync::Arc::new(path.to_path_buf()),
        line: 1,
        col: 1,
    };
    load_with(path, &Options::new(at))
}

/// The camera of `scene` moved to a frame of a Tachyon camera file (`-camfile`): VIEWDIR,
/// UPDIR and CENTER as Tachyon writes them, mapped as a CAMERA's are (mirrored); zoom,
/// window, projection and lens stay. The error says which vector is unusable.
pub fn camera_at(
    camera: &crate::desc::CameraDesc,
    viewdir: [f64; 3],
    updir: [f64; 3],
    center: [f64; 3],
) -> Result<crate::desc::CameraDesc, String> {
    map::moved_camera(camera, viewdir, updir, center)
}

/// [`load`] with Tachyon's command-line overrides (`luxon tachyon`).
pub fn load_with(path: &Path, options: &Options) -> Result<SceneDesc, SceneError> {
    map::to_desc(parse::parse_file(path, options.max_text)?, options)
}
