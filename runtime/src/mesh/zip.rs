//! A ZIP archive writer, as much of the format (PKWARE's APPNOTE.TXT, 6.3) as a 3MF package
//! needs: entries stored or deflated (`flate2`), CRC-32 (`crc32fast`), one central directory,
//! no ZIP64 (an entry or archive of 4 GiB or more is refused).
//!
//! An entry is compressed as it is written ([`Deflated`]), so that the 3MF model's text is
//! never held whole, only its compressed bytes.

use flate2::write::DeflateEncoder;
use flate2::Compression;
use std::io::{self, Write};

/// An entry's bytes, compressed as they are written, with their CRC-32 and length.
#[derive(Debug)]
pub struct Deflated {
    encoder: DeflateEncoder<Vec<u8>>,
    crc: crc32fast::Hasher,
    size: u64,
}

impl Default for Deflated {
    fn default() -> Self {
        Deflated {
            encoder: DeflateEncoder::new(Vec::new(), Compression::fast()),
            crc: crc32fast::Hasher::new(),
            size: 0,
        }
    }
}

impl Write for Deflated {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.encoder.write(buf)?;
        self.crc.update(&buf[..n]);
        self.size += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.encoder.flush()
    }
}

impl Deflated {
    /// The entry named `name`, its compression finished.
    pub fn finish(self, name: &str) -> io::Result<Entry> {
        Ok(Entry {
            name: name.to_string(),
            crc: self.crc.finalize(),
            size: self.size,
            method: 8,
            data: self.encoder.finish()?,
        })
    }
}

/// One file of an archive, ready to be written.
#[derive(Debug, Clone)]
pub struct Entry {
    name: String,
    crc: u32,
    size: u64,
    /// 0: stored, 8: deflated.
    method: u16,
    data: Vec<u8>,
}

impl Entry {
    /// The file `name` holding `bytes`, stored as they are.
    pub fn stored(name: &str, bytes: &[u8]) -> Entry {
        Entry {
            name: name.to_string(),
            crc: crc32fast::hash(bytes),
            size: bytes.len() as u64,
            method: 0,
            data: bytes.to_vec(),
        }
    }
}

/// MS-DOS date of 1980-01-01 (the earliest a ZIP can state), time 00:00.
const DATE: u16 = (1 << 5) | 1;

fn too_large(what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{what} reaches 4 GiB, more than a ZIP without its 64-bit extension can hold"),
    )
}

fn u32_of(x: u64, what: &str) -> io::Result<u32> {
    u32::try_from(x)
        .ok()
        .filter(|&v| v != u32::MAX)
        .ok_or_else(|| too_large(what))
}

/// The archive of `entries`, in their order.
pub fn archive(entries: &[Entry]) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    for e in entries {
        let offset = u32_of(out.len() as u64, "the archive")?;
        let (csize, size) = (
            u32_of(e.data.len() as u64, &e.name)?,
            u32_of(e.size, &e.name)?,
        );
        let name = e.name.as_bytes();
        // The fields the local header and the central directory's record share, from
        // "version needed" (2.0: deflate) to the name's length.
        let mut common = Vec::with_capacity(26);
        common.extend_from_slice(&20u16.to_le_bytes());
        common.extend_from_slice(&0u16.to_le_bytes()); // flags
        common.extend_from_slice(&e.method.to_le_bytes());
        common.extend_from_slice(&0u16.to_le_bytes()); // time
        common.extend_from_slice(&DATE.to_le_bytes());
        common.extend_from_slice(&e.crc.to_le_bytes());
        common.extend_from_slice(&csize.to_le_bytes());
        common.extend_from_slice(&size.to_le_bytes());
        common.extend_from_slice(&(name.len() as u16).to_le_bytes());
        common.extend_from_slice(&0u16.to_le_bytes()); // extra field's length

        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        out.extend_from_slice(&common);
        out.extend_from_slice(name);
        out.extend_from_slice(&e.data);

        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes()); // made by: MS-DOS, 2.0
        central.extend_from_slice(&common);
        central.extend_from_slice(&[0; 6]); // comment length, disk, internal attributes
        central.extend_from_slice(&0u32.to_le_bytes()); // external attributes
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name);
    }
    let start = u32_of(out.len() as u64, "the archive")?;
    let length = u32_of(central.len() as u64, "the archive's directory")?;
    out.extend_from_slice(&central);
    let count = u16::try_from(entries.len()).map_err(|_| too_large("the entries"))?;
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0; 4]); // this disk, the directory's disk
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&length.to_le_bytes());
    out.extend_from_slice(&start.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes()); // comment length
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CRC-32 of the check string of the ZIP polynomial (0xCBF43926), and the layout of
    /// a one-entry archive: local header, name, data, directory record, end record.
    #[test]
    fn a_stored_entry_has_its_crc_and_offsets() {
        let e = Entry::stored("a.txt", b"123456789");
        assert_eq!(e.crc, 0xCBF4_3926);
        let z = archive(&[e]).expect("small");
        assert_eq!(&z[..4], b"PK\x03\x04");
        let local = 30 + 5 + 9;
        assert_eq!(&z[local..local + 4], b"PK\x01\x02");
        // The record: 46 bytes and the name; its last field the local header's offset.
        assert_eq!(z.len() - 22, local + 46 + 5);
        assert_eq!(
            u32::from_le_bytes(z[local + 42..local + 46].try_into().unwrap()),
            0
        );
        let end = z.len() - 22;
        assert_eq!(&z[end..end + 4], b"PK\x05\x06");
        assert_eq!(
            u32::from_le_bytes(z[end + 16..end + 20].try_into().unwrap()),
            local as u32
        );
    }
}
