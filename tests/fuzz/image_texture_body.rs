//! Image textures from bytes: the header read ([`probe_reader`]), the decode planned within a
//! cap ([`plan`]) and the texels decoded ([`decode_reader`]), as the `image` texture does on
//! create and on first use. The decoded levels must fit the cap, have the planned sizes and
//! hold finite texels. Shared by the `image_texture` fuzz target and the test that runs it over
//! the seeds (`plugins/textures/tests/fuzz_regressions.rs`).

use luxon_textures::decode::{decode_reader, plan, probe_reader, Level};
use std::io::Cursor;

/// The decode cap: small, so that the fuzzer's memory stays bounded.
pub const CAP: u64 = 64 << 20;

/// Probes, plans and decodes `data`; panics if a decode breaks the cap or the plan.
pub fn run(data: &[u8]) -> Result<Vec<Level>, String> {
    // Named `.tga`: bytes without a signature are tried as TGA (which has none); PNG, JPEG,
    // PNM and OpenEXR are recognised by their content.
    let name = "fuzz.tga";
    let header = probe_reader(Cursor::new(data), name).map_err(|e| e.message)?;
    let plan = plan(name, &header, CAP).map_err(|e| e.message)?;
    let levels = decode_reader(Cursor::new(data), &header, true, &plan)?;
    let bytes: u64 = levels.iter().map(|l| l.bytes() as u64).sum();
    assert!(bytes <= CAP, "{bytes} bytes decoded, over the cap of {CAP}");
    let mut size = plan.size(&header);
    for level in &levels {
        assert_eq!((level.width, level.height), size, "{header:?}, {plan:?}");
        size = ((size.0 / 2).max(1), (size.1 / 2).max(1));
    }
    assert_eq!(levels.last().map(|l| (l.width, l.height)), Some((1, 1)));
    assert!(
        levels
            .iter()
            .all(|l| l.texels().iter().flatten().all(|v| v.is_finite())),
        "non-finite texels"
    );
    Ok(levels)
}
