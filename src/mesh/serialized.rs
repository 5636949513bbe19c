//! Mitsuba's `serialized` meshes (file versions 3 and 4): a file of one or more meshes, each a
//! little-endian header (`0x041C`, the version) and a zlib stream of flags, the name (version
//! 4), the vertex and triangle counts, positions, normals, texture coordinates and colours as
//! the flags say (single or double precision), and 32-bit triangle indices. A dictionary at the
//! end gives each mesh's offset (64-bit in version 4, 32-bit in version 3) and their count.

use super::MeshData;
use glam::{DVec3, Vec2};
use std::io::Read;
use std::path::Path;

const FORMAT: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;
/// Most vertices or triangles a mesh may declare (a larger count is a corrupt file).
const MAX_COUNT: u64 = 1 << 31;

/// Read mesh number `index` of the serialized file at `path`.
pub fn load_serialized(path: &Path, index: u32) -> Result<MeshData, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read mesh file: {e}"))?;
    parse(&bytes, index)
}

fn u16_at(b: &[u8], at: usize) -> Result<u16, String> {
    b.get(at..at + 2)
        .map(|s| u16::from_le_bytes([s[0], s[1]]))
        .ok_or_else(|| "the file is too short (truncated)".to_string())
}

/// Mesh `index` of a serialized file's bytes.
pub fn parse(bytes: &[u8], index: u32) -> Result<MeshData, String> {
    if u16_at(bytes, 0)? != FORMAT {
        return Err("not a Mitsuba serialized mesh (its first two bytes are not 0x041C)".into());
    }
    let version = u16_at(bytes, 2)?;
    if version != 3 && version != 4 {
        return Err(format!(
            "serialized file version {version}: rtis reads versions 3 and 4"
        ));
    }
    // Where mesh `index` starts: the dictionary at the end of the file.
    let start = if index == 0 {
        0
    } else {
        let n = bytes.len();
        let count_at = n
            .checked_sub(4)
            .ok_or("the file is too short (truncated)")?;
        let count = u32::from_le_bytes(bytes[count_at..].try_into().map_err(|_| "truncated")?);
        if index >= count {
            return Err(format!(
                "shape_index {index}: the file holds {count} mesh(es), 0 to {}",
                count.saturating_sub(1)
            ));
        }
        let back = (count - index) as usize;
        let offset = if version == 4 {
            let at = count_at
                .checked_sub(8 * back)
                .ok_or("the file's dictionary is cut short")?;
            u64::from_le_bytes(bytes[at..at + 8].try_into().map_err(|_| "truncated")?) as usize
        } else {
            let at = count_at
                .checked_sub(4 * back)
                .ok_or("the file's dictionary is cut short")?;
            u32::from_le_bytes(bytes[at..at + 4].try_into().map_err(|_| "truncated")?) as usize
        };
        if offset.checked_add(4).is_none_or(|end| end > bytes.len())
            || u16_at(bytes, offset)? != FORMAT
        {
            return Err(format!(
                "mesh {index}'s offset {offset} does not start a mesh"
            ));
        }
        offset
    };
    let mut z = flate2::read::ZlibDecoder::new(&bytes[start + 4..]);
    // Read as the data comes: a header's counts never decide an allocation on their own.
    let mut read = |n: usize| -> Result<Vec<u8>, String> {
        let mut buf = Vec::new();
        (&mut z)
            .take(n as u64)
            .read_to_end(&mut buf)
            .map_err(|e| format!("the compressed mesh data is corrupt ({e})"))?;
        if buf.len() < n {
            return Err("the compressed mesh data is cut short (truncated)".into());
        }
        Ok(buf)
    };
    let u32_of = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let u64_of = |b: &[u8]| u64::from_le_bytes(b[..8].try_into().unwrap_or([0; 8]));
    let flags = u32_of(&read(4)?);
    if version == 4 {
        // The name, up to its NUL.
        let mut len = 0;
        while read(1)?[0] != 0 {
            len += 1;
            if len > 1 << 16 {
                return Err("a mesh name without its end".into());
            }
        }
    }
    let (vertices, triangles) = (u64_of(&read(8)?), u64_of(&read(8)?));
    if vertices > MAX_COUNT || triangles > MAX_COUNT {
        return Err(format!(
            "{vertices} vertices and {triangles} triangles: too many (a corrupt file?)"
        ));
    }
    let (nv, nt) = (vertices as usize, triangles as usize);
    let double = flags & DOUBLE_PRECISION != 0;
    let width = if double { 8 } else { 4 };
    let mut floats = |count: usize| -> Result<Vec<f64>, String> {
        let b = read(count * width)?;
        Ok(b.chunks_exact(width)
            .map(|c| {
                if double {
                    f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))
                } else {
                    f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64
                }
            })
            .collect())
    };
    let p = floats(3 * nv)?;
    let mut mesh = MeshData {
        positions: p
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect(),
        ..MeshData::default()
    };
    if let Some(bad) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("vertex {bad} is not finite"));
    }
    // The file's face-normals flag is ignored, as Mitsuba 3 ignores it (a shape's
    // `face_normals` says it).
    if flags & HAS_NORMALS != 0 {
        let n = floats(3 * nv)?;
        mesh.normals = n
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]).normalize_or_zero())
            .collect();
        if mesh.normals.contains(&DVec3::ZERO) {
            mesh.normals.clear();
        }
    }
    if flags & HAS_TEXCOORDS != 0 {
        let t = floats(2 * nv)?;
        mesh.uvs = t
            .chunks_exact(2)
            .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
            .collect();
    }
    if flags & HAS_COLORS != 0 {
        floats(3 * nv)?;
    }
    let idx = read(12 * nt)?;
    for (k, f) in idx.chunks_exact(12).enumerate() {
        let face = [u32_of(&f[0..4]), u32_of(&f[4..8]), u32_of(&f[8..12])];
        if let Some(&bad) = face.iter().find(|&&i| i as usize >= nv) {
            return Err(format!(
                "triangle {k} refers to vertex {bad}, but the mesh has {nv} vertices"
            ));
        }
        mesh.faces.push(face);
    }
    if mesh.faces.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// A version-4 file of two meshes: a triangle, and a quad with texture coordinates.
    fn file() -> Vec<u8> {
        let mut out = Vec::new();
        let mut offsets = Vec::new();
        for quad in [false, true] {
            offsets.push(out.len() as u64);
            out.extend(FORMAT.to_le_bytes());
            out.extend(4u16.to_le_bytes());
            let mut raw = Vec::new();
            let flags = if quad { HAS_TEXCOORDS | 0x1000 } else { 0x1000 };
            raw.extend(flags.to_le_bytes());
            raw.extend(b"mesh\0");
            let (v, f): (Vec<[f32; 3]>, Vec<[u32; 3]>) = if quad {
                (
                    vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
                    vec![[0, 1, 2], [0, 2, 3]],
                )
            } else {
                (
                    vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
                    vec![[0, 1, 2]],
                )
            };
            raw.extend((v.len() as u64).to_le_bytes());
            raw.extend((f.len() as u64).to_le_bytes());
            for p in &v {
                for c in p {
                    raw.extend(c.to_le_bytes());
                }
            }
            if quad {
                for p in &v {
                    raw.extend(p[0].to_le_bytes());
                    raw.extend(p[1].to_le_bytes());
                }
            }
            for t in &f {
                for i in t {
                    raw.extend(i.to_le_bytes());
                }
            }
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            z.write_all(&raw).unwrap();
            out.extend(z.finish().unwrap());
        }
        for o in &offsets {
            out.extend(o.to_le_bytes());
        }
        out.extend((offsets.len() as u32).to_le_bytes());
        out
    }

    /// Each mesh of the file by its index; an index past the last, and a cut file, say why.
    #[test]
    fn meshes_by_index() {
        let b = file();
        let m0 = parse(&b, 0).unwrap();
        assert_eq!((m0.positions.len(), m0.faces.len()), (3, 1));
        let m1 = parse(&b, 1).unwrap();
        assert_eq!(m1.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m1.uvs[2], Vec2::new(1.0, 1.0));
        let e = parse(&b, 2).unwrap_err();
        assert!(e.contains("holds 2 mesh"), "{e}");
        let e = parse(&b[..40], 0).unwrap_err();
        assert!(e.contains("cut short") || e.contains("corrupt"), "{e}");
        // A header that declares 2^31 vertices in a few bytes is refused without allocating.
        let mut big = Vec::new();
        big.extend(FORMAT.to_le_bytes());
        big.extend(3u16.to_le_bytes());
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        let mut raw = 0x1000u32.to_le_bytes().to_vec();
        raw.extend((1u64 << 31).to_le_bytes());
        raw.extend(1u64.to_le_bytes());
        z.write_all(&raw).unwrap();
        big.extend(z.finish().unwrap());
        let e = parse(&big, 0).unwrap_err();
        assert!(e.contains("cut short"), "{e}");
    }
}
