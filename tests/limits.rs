//! Memory in proportion to the scene's content, not to what a file claims or decompresses to:
//! checked by running `luxon` under an address-space limit (`common::limits::run_limited`).
#![cfg(target_os = "linux")]

mod common;

use common::limits::run_limited;
use common::*;
use std::io::Write;

/// A 512³ u8 raw volume of zeros as a gzip file of 16 identical members (about 400 KB): 128 MiB
/// once decompressed, and entirely background. It used to cost the whole decompressed file (held
/// at once) plus 512 MiB of f32 bricks; now the reader streams slabs of 8 slices and the host
/// stores no background brick, so the render fits in little more than a tiny one needs.
#[test]
fn an_empty_gzip_volume_renders_in_little_memory() {
    let dir = temp_dir("limits-empty-volume");
    let mut member = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    member.write_all(&vec![0u8; 8 << 20]).unwrap();
    let member = member.finish().unwrap();
    let mut file = std::fs::File::create(dir.join("zeros.raw.gz")).unwrap();
    for _ in 0..16 {
        file.write_all(&member).unwrap();
    }
    drop(file);
    std::fs::write(
        dir.join("v.ron"),
        r#"Scene(
    camera: (position: (0, 0, -3000), look_at: (0, 0, 0)),
    volumes: [(plugin: "raw", params: (file: "zeros.raw.gz", dims: (512, 512, 512), origin: (-256, -256, -256)))],
    render: (width: 16, height: 16),
)"#,
    )
    .unwrap();
    let out = run_limited(
        &["render", "v.ron", "-o", "v.png", "--threads", "2"],
        &dir,
        288 << 20,
        120,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("v.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 256³ u8 raw volume of random bytes (16 MiB), written by the test.
fn random_u8_volume(dir: &std::path::Path) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let bytes: Vec<u8> = (0..256 * 256 * 256)
        .map(|_| {
            // xorshift64*: every brick varies, so none collapses.
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 56) as u8
        })
        .collect();
    std::fs::write(dir.join("noise.raw"), bytes).unwrap();
    std::fs::write(
        dir.join("v.ron"),
        r#"Scene(
    camera: (position: (0, 0, -2000), look_at: (0, 0, 0)),
    volumes: [(plugin: "raw", name: "noise", params: (file: "noise.raw", dims: (256, 256, 256), origin: (-128, -128, -128)),
               render: (transfer: (preset: "grayscale")))],
    render: (width: 16, height: 16),
)"#,
    )
    .unwrap();
}

/// A u8 volume is stored a byte per voxel (u8 bricks), not as f32: `check` reports its bricks
/// and a size near the voxel count, and a render fits a limit that f32 bricks (64 MiB) would
/// not.
#[test]
fn a_u8_volume_costs_a_byte_per_voxel() {
    let dir = temp_dir("limits-u8-volume");
    random_u8_volume(&dir);
    let voxels = 256u64 * 256 * 256;
    let out = run_limited(&["check", "v.ron"], &dir, 512 << 20, 120);
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(out.status.code(), Some(0), "{}{text}", stderr(&out));
    let line = text
        .lines()
        .find(|l| l.starts_with("volume     `noise` (raw)"))
        .unwrap_or_else(|| panic!("no volume line in:\n{text}"));
    assert!(line.ends_with("(bricks: 32768 u8)"), "{line}");
    let mib: f64 = line
        .split(", ")
        .find_map(|part| part.split_once(" MiB").map(|(n, _)| n.parse().unwrap()))
        .unwrap_or_else(|| panic!("no size in {line}"));
    assert!(
        mib * 1024.0 * 1024.0 <= 1.1 * voxels as f64 + 16.0 * 1024.0 * 1024.0,
        "{line}"
    );

    let out = run_limited(
        &["render", "v.ron", "-o", "v.png", "--threads", "2"],
        &dir,
        (288 << 20) + voxels,
        120,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("v.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 16384² image needs 4 GiB of f32 pixels: over a 1 GiB budget it is an error naming the
/// image, found before anything that size is allocated (the run fits a 1.5 GiB address space;
/// it used to abort).
#[test]
fn an_image_over_the_budget_is_an_error_before_it_is_allocated() {
    let dir = temp_dir("limits-huge-image");
    std::fs::write(
        dir.join("s.ron"),
        r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1))],
)"#,
    )
    .unwrap();
    let args = [
        "render",
        "s.ron",
        "--res",
        "16384x16384",
        "-o",
        "big.png",
        "--threads",
        "2",
    ];
    let with = |extra: &[&'static str]| {
        let all: Vec<&str> = args.iter().chain(extra).copied().collect();
        run_limited(&all, &dir, 3 << 29, 120)
    };
    let out = with(&["--memory", "1G"]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert_eq!(
        e,
        "luxon: error: the image (16384x16384, 4 f32 channels) needs 4 GiB more, but the memory \
         budget of 1 GiB (from --memory) has 1 GiB left (in use: nothing); raise it with \
         --memory or `render: (memory: ...)`\n"
    );
    assert!(!dir.join("big.png").exists());
    // Without --memory, the default follows the address-space limit the run is under.
    let out = with(&[]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("needs 4 GiB more, but the memory budget of 1.1 GiB (75% of 1.5 GiB RLIMIT_AS)"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A 256³ f32 raw volume (64 MiB of bricks): over a 64 MiB budget it is an error naming the
/// volume and the budget; within 256 MiB it renders.
#[test]
fn a_volume_over_the_budget_is_an_error_naming_it() {
    let dir = temp_dir("limits-f32-volume");
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut bytes = Vec::with_capacity(256 * 256 * 256 * 4);
    for _ in 0..256 * 256 * 256 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let v = (state >> 40) as f32 / (1u64 << 24) as f32;
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(dir.join("v.raw"), bytes).unwrap();
    std::fs::write(
        dir.join("v.ron"),
        r#"Scene(
    camera: (position: (0, 0, -2000), look_at: (0, 0, 0)),
    volumes: [
        (plugin: "raw", name: "v", params: (file: "v.raw", dims: (256, 256, 256), format: "f32", origin: (-128, -128, -128)),
         render: (transfer: (preset: "grayscale"))),
    ],
    render: (width: 16, height: 16),
)"#,
    )
    .unwrap();
    let render = |memory: &str| {
        let args = [
            "render",
            "v.ron",
            "-o",
            "v.png",
            "--threads",
            "2",
            "--memory",
            memory,
        ];
        run_limited(&args, &dir, 1 << 30, 120)
    };
    let out = render("64M");
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.starts_with("luxon: error: v.ron:4:44: plugin `raw` (libluxon_volume_raw.so) failed: "),
        "{e}"
    );
    assert!(
        e.contains("volume `v` (its storage so far: ")
            && e.contains("the memory budget of 64 MiB (from --memory) has ")
            && e.contains("(in use: volumes "),
        "{e}"
    );
    assert!(!dir.join("v.png").exists());
    let out = render("256M");
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("v.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The scene's `memory` and `texture_cache` settings: a size that does not parse is an error at
/// its line and column; one that does sets the budget `check` prints, with the texture cache
/// reserved for a scene with textures (by default a quarter of the budget, at most 1 GiB).
#[test]
fn the_memory_setting_is_checked_and_printed() {
    let dir = temp_dir("limits-memory-setting");
    let scene = |render: &str| {
        format!(
            r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    textures: {{ "t": (plugin: "checker") }},
    materials: {{ "m": (texture: "t") }},
    objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "m")],
    render: ({render}),
)"#
        )
    };
    let check = |render: &str, extra: &[&str]| {
        std::fs::write(dir.join("s.ron"), scene(render)).unwrap();
        let mut args = vec!["check", "s.ron"];
        args.extend(extra);
        run_limited(&args, &dir, 1 << 30, 60)
    };
    let out = check(r#"memory: "1.5 X""#, &[]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        stderr(&out),
        "luxon: error: s.ron:6:22: `memory` is \"1.5 X\": `X` is not a unit; expected a size \
         such as 512M, 6G, \"1.5 GiB\" or 50%\n"
    );
    let out = check(r#"width: 8, texture_cache: "10%""#, &[]);
    assert!(
        stderr(&out).contains(":6:39: `texture_cache` is \"10%\"; expected a size in bytes"),
        "{}",
        stderr(&out)
    );

    let memory_line = |out: &std::process::Output| {
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        assert_eq!(out.status.code(), Some(0), "{}{text}", stderr(out));
        text.lines()
            .find(|l| l.starts_with("memory "))
            .unwrap_or_else(|| panic!("no memory line in:\n{text}"))
            .to_string()
    };
    let line = memory_line(&check(r#"memory: "2 GiB""#, &[]));
    assert!(
        line.starts_with(
            "memory     budget 2 GiB (from the scene's `render: (memory: ...)`); the scene holds "
        ) && line.contains("texture cache 512 MiB"),
        "{line}"
    );
    let line = memory_line(&check(
        r#"memory: "2 GiB", texture_cache: "100M""#,
        &["--memory", "1G"],
    ));
    assert!(
        line.starts_with("memory     budget 1 GiB (from --memory)")
            && line.contains("texture cache 100 MiB"),
        "{line}"
    );
    let out = check("", &["--memory", "6X"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).starts_with(
            "luxon: error: invalid value '6X' for '--memory <SIZE>': expected a size such as 512M"
        ),
        "{}",
        stderr(&out)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An RGB 8-bit PNG of zeros whose header says `w × h` but whose data holds only `rows` rows
/// (all of them when `rows == h`), compressed row by row: a 16000² file is about 750 KB.
fn zero_png(path: &std::path::Path, w: u32, h: u32, rows: u32) {
    let chunk = |out: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        out.extend((data.len() as u32).to_be_bytes());
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        out.extend(kind);
        out.extend(data);
        out.extend(crc.sum().to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    let row = vec![0u8; 1 + 3 * w as usize];
    for _ in 0..rows {
        z.write_all(&row).unwrap();
    }
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut png, b"IHDR", &ihdr);
    chunk(&mut png, b"IDAT", &z.finish().unwrap());
    chunk(&mut png, b"IEND", &[]);
    std::fs::write(path, png).unwrap();
}

/// A sphere with an image texture, rendered 32×32 to `t.png`.
fn texture_scene(dir: &std::path::Path, image: &str) {
    std::fs::write(
        dir.join("t.ron"),
        format!(
            r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    lights: [Point(position: (0, 5, -5))],
    textures: {{ "img": (plugin: "image", params: (file: "{image}", mapping: spherical, center: (0, 0, 0))) }},
    materials: {{ "m": (texture: "img") }},
    objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "m")],
    render: (width: 32, height: 32),
)"#
        ),
    )
    .unwrap();
}

/// A 16000² PNG (750 KB) used to be decoded whole, copied twice and MIP-mapped in float: about
/// 7 GB for a 32×32 render, an abort under a memory limit. Now it is streamed row by row and
/// only the MIP levels that fit the decode cap are kept, with a warning. The cap is the texture
/// cache, by default a quarter of the memory budget: under a 700 MiB address space the budget is
/// 525 MiB, so 131 MiB, and the image is used from 2000×2000 on; with `--memory 4G` the cache
/// is 1 GiB, and it is used from 4000×4000 on (341 MB, still within the address space).
#[test]
fn a_huge_png_texture_is_decoded_within_the_cap() {
    let dir = temp_dir("limits-huge-png");
    zero_png(&dir.join("big.png"), 16000, 16000, 16000);
    texture_scene(&dir, "big.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "t.ron", "-o", "t.png", "--threads", "2"];
        args.extend(extra);
        run_limited(&args, &dir, 700 << 20, 300)
    };
    let out = render(&[]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{e}");
    assert!(
        e.contains("image `big.png` (16000x16000) is decoded at 2000x2000 to stay within the texture memory cap of 131.2 MiB"),
        "{e}"
    );
    assert!(dir.join("t.png").is_file());
    let out = render(&["--memory", "4G"]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{e}");
    assert!(
        e.contains("image `big.png` (16000x16000) is decoded at 4000x4000 to stay within the texture memory cap of 1.0 GiB"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A PNG whose header claims 65535² texels but holds two rows: an error naming the file, and
/// nothing allocated for what the header claims (levels are allocated as their rows arrive).
#[test]
fn a_png_header_that_lies_fails_the_render_without_allocating() {
    let dir = temp_dir("limits-lying-png");
    zero_png(&dir.join("liar.png"), 65535, 65535, 2);
    texture_scene(&dir, "liar.png");
    let out = run_limited(
        &["render", "t.ron", "-o", "t.png", "--threads", "2"],
        &dir,
        288 << 20,
        120,
    );
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("cannot decode image") && e.contains("liar.png"),
        "{e}"
    );
    assert!(!dir.join("t.png").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An NFF file of 2 million spheres (32 MB of text, 61 MiB of imported geometry) with a
/// `resolution` of 32×32.
fn many_spheres_nff(path: &std::path::Path) {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    f.write_all(
        b"v\nfrom 0 0 -400\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 32 32\n\
          l 0 0 -500\nf 1 0 0 1 0 0 0 0\n",
    )
    .unwrap();
    for i in 0..2_000_000i64 {
        let (x, y, z) = (i % 126 - 63, (i / 126) % 126 - 63, i / 15876);
        writeln!(f, "s {x} {y} {z} 0.4").unwrap();
    }
    f.flush().unwrap();
}

/// The geometry an importer reads is charged to the memory budget: an NFF file holding more
/// than the budget is an error naming the file and the budget, found while it is read (the
/// run ends in well under a second); one whose import fits but whose scene does not is an error
/// naming it too; with enough memory it renders. Nothing aborts under the address-space limit.
#[test]
fn an_nff_file_over_the_budget_is_an_error_naming_it() {
    let dir = temp_dir("limits-big-nff");
    many_spheres_nff(&dir.join("big.nff"));
    let render = |memory: &str, limit: u64| {
        let args = [
            "render",
            "big.nff",
            "-o",
            "b.png",
            "--threads",
            "2",
            "--no-cache",
            "--memory",
            memory,
        ];
        run_limited(&args, &dir, limit, 120)
    };
    let out = render("32M", 512 << 20);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.starts_with("luxon: error: cannot import `big.nff`: its ")
            && e.contains(" spheres, 0 cones and 0 triangles up to line ")
            && e.ends_with(
                "more than the 32 MiB left for imported geometry; the memory budget is 32 MiB \
                 (from --memory); raise it with --memory\n"
            ),
        "{e}"
    );
    // The import fits in 64 MiB, the imported spheres and their scene arrays together do not.
    let out = render("64M", 512 << 20);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.starts_with("luxon: error: big.nff:")
            && e.contains("the memory budget of 64 MiB (from --memory)")
            && e.contains("in use: imported geometry 61.0 MiB"),
        "{e}"
    );
    assert!(!dir.join("b.png").exists());
    let out = render("1G", 3 << 29);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("b.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An OBJ file's geometry is estimated from its statements before it is read into meshes:
/// over the budget it is an error naming the file; within it the mesh renders.
#[test]
fn an_obj_file_over_the_budget_is_an_error_naming_it() {
    let dir = temp_dir("limits-big-obj");
    let n = 300;
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("grid.obj")).unwrap());
    for j in 0..n {
        for i in 0..n {
            writeln!(f, "v {i} {j} 0").unwrap();
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i + 1;
            writeln!(f, "f {a} {} {} {}", a + 1, a + n + 1, a + n).unwrap();
        }
    }
    drop(f);
    let render = |memory: &str| {
        let args = [
            "render",
            "grid.obj",
            "-o",
            "g.png",
            "--res",
            "32x32",
            "--threads",
            "2",
            "--memory",
            memory,
        ];
        run_limited(&args, &dir, 1 << 30, 120)
    };
    let out = render("16M");
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.starts_with(
            "luxon: error: cannot import `grid.obj`: its 90000 vertices and 178802 triangles need "
        ) && e.ends_with(
            "more than the 16 MiB left for imported geometry; the memory budget is 16 MiB (from \
             --memory); raise it with --memory\n"
        ),
        "{e}"
    );
    let out = render("256M");
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("g.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}
