//! Files. The size of the file is checked against its header before the payload is read, so a
//! damaged header can never make the reader allocate more than the file holds.

use std::io::Read;
use std::path::Path;

use crate::error::Error;
use crate::table::{Dims, HEADER_BYTES, MerlTable, check_size, parse_header};

/// Reads and validates a MERL `.binary` file.
pub fn read_file(path: &Path) -> Result<MerlTable, Error> {
    let mut file = std::fs::File::open(path)?;
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
    MerlTable::parse(&bytes)
}
