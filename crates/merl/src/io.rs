//! Files. The size of the file is checked against its header before the payload is read, so a
//! damaged header can never make the reader allocate more than the file holds; only a regular file
//! is read (a FIFO or a device is refused without blocking).

use std::io::Read;
use std::path::Path;

use crate::error::Error;
use crate::table::{Dims, HEADER_BYTES, MerlTable, check_size, parse_header};

/// The largest MERL file, in bytes: a table of 90 x 90 x 360 cells.
pub const MAX_FILE_BYTES: u64 = Dims::MERL_FULL_PHI.file_bytes();

/// Reads and validates a MERL `.binary` file.
pub fn read_file(path: &Path) -> Result<MerlTable, Error> {
    MerlTable::parse(&read_bytes(path)?)
}

/// The bytes of a MERL `.binary` file whose header and size agree (what [`read_file`] parses),
/// for callers that also hash them: the file is opened as a regular file only, without blocking
/// ([`fsguard::open_regular`]), its header checked against its size from its metadata, and then
/// at most the size the header promises is read.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    let mut file = fsguard::open_regular(path)?;
    let file_bytes = file.metadata()?.len();
    let mut header = Vec::with_capacity(HEADER_BYTES);
    file.by_ref().take(HEADER_BYTES as u64).read_to_end(&mut header)?;
    let dims = Dims::from_header(parse_header(&header)?)?;
    check_size(dims, file_bytes)?;
    let mut bytes = header;
    bytes.reserve_exact((file_bytes as usize).saturating_sub(HEADER_BYTES));
    // Read at most what the header promises: a file that grew since `metadata` is caught by
    // `parse`, not by an unbounded read.
    file.take(file_bytes - HEADER_BYTES as u64 + 1).read_to_end(&mut bytes)?;
    check_size(dims, bytes.len() as u64)?;
    Ok(bytes)
}
