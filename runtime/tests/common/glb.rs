//! A binary glTF file written for a test (the mesh and memory binaries include it): its JSON
//! chunk padded with spaces, then its binary chunk.

/// A binary glTF file of `json` and `bin`.
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut b = b"glTF".to_vec();
    for n in [2, 20 + json.len() + 8 + bin.len(), json.len()] {
        b.extend_from_slice(&(n as u32).to_le_bytes());
    }
    b.extend_from_slice(b"JSON");
    b.extend_from_slice(&json);
    b.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    b.extend_from_slice(b"BIN\0");
    b.extend_from_slice(bin);
    b
}
