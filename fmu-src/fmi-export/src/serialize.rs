//! FMU states: the in-memory snapshot behind `fmi2GetFMUstate` and its byte
//! form for `fmi2SerializeFMUstate`.
//!
//! Byte layout (little endian): magic `FRICFMI2`, format version (u32), GUID
//! length (u32) and bytes, instance state (u32), initialised flag (u8), time
//! (f64), then three f64 arrays each preceded by its length (u64): variable
//! values, input slopes, model state; last an FNV-1a 64 checksum of all
//! preceding bytes. Every field is checked when reading, so a truncated,
//! corrupted or foreign state is refused with the reason.

use crate::state_machine::State;

const MAGIC: &[u8; 8] = b"FRICFMI2";
const FORMAT_VERSION: u32 = 1;

#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// The model's GUID (`ModelInfo::guid` itself: compared by address
    /// first).
    pub guid: &'static str,
    pub state: State,
    pub initialized: bool,
    pub time: f64,
    pub values: Vec<f64>,
    pub slopes: Vec<f64>,
    /// Whether a slope in `slopes` may be non-zero (false: all are zero,
    /// and a copy of them can be skipped). Not serialized.
    pub sloped: bool,
    pub model_state: Vec<f64>,
    /// The instance's parameter version when taken
    /// ([`crate::instance::Instance`]: unchanged means no parameter was set
    /// since); `u64::MAX` (unknown) for a deserialized state. Not serialized.
    pub parameters_version: u64,
}

fn fnv1a(bytes: &[u8]) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        hash ^= *b as u64;
        hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
    hash
}

impl Snapshot {
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(
            64 + self.guid.len()
                + 8 * (self.values.len() + self.slopes.len() + self.model_state.len()),
        );
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(self.guid.len() as u32).to_le_bytes());
        out.extend_from_slice(self.guid.as_bytes());
        out.extend_from_slice(&self.state.to_u32().to_le_bytes());
        out.push(self.initialized as u8);
        out.extend_from_slice(&self.time.to_le_bytes());
        for array in [&self.values, &self.slopes, &self.model_state] {
            out.extend_from_slice(&(array.len() as u64).to_le_bytes());
            for x in array.iter() {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        let checksum = fnv1a(&out);
        out.extend_from_slice(&checksum.to_le_bytes());
        out
    }

    /// Parse and check a serialized state for the model with `guid` and
    /// `n_values` variables.
    pub fn from_bytes(
        bytes: &[u8],
        guid: &'static str,
        n_values: usize,
    ) -> Result<Snapshot, String> {
        if bytes.len() < MAGIC.len() + 8 {
            return Err(format!(
                "serialized state is {} bytes, too short to be one",
                bytes.len()
            ));
        }
        let (body, tail) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(tail.try_into().expect("8 bytes"));
        let mut r = Reader {
            bytes: body,
            pos: 0,
        };
        if r.take(8)? != MAGIC {
            return Err(
                "serialized state does not start with the magic FRICFMI2: not a state of this FMU"
                    .into(),
            );
        }
        let version = r.u32()?;
        if version != FORMAT_VERSION {
            return Err(format!(
                "serialized state has format version {version}, expected {FORMAT_VERSION}"
            ));
        }
        if fnv1a(body) != stored {
            return Err(
                "serialized state checksum mismatch: the bytes are corrupted or truncated".into(),
            );
        }
        let guid_len = r.u32()? as usize;
        let stored_guid = std::str::from_utf8(r.take(guid_len)?)
            .map_err(|_| "serialized state GUID is not UTF-8".to_string())?;
        if stored_guid != guid {
            return Err(format!(
                "serialized state belongs to the FMU with GUID {stored_guid}, not {guid}"
            ));
        }
        let state_bits = r.u32()?;
        let state = State::from_u32(state_bits).ok_or_else(|| {
            format!("serialized state has an invalid instance state {state_bits}")
        })?;
        let initialized = match r.take(1)?[0] {
            0 => false,
            1 => true,
            b => return Err(format!("serialized state has an invalid flag byte {b}")),
        };
        let time = r.f64()?;
        let values = r.f64_array()?;
        if values.len() != n_values {
            return Err(format!(
                "serialized state holds {} variable values, this FMU has {n_values}",
                values.len()
            ));
        }
        let slopes = r.f64_array()?;
        if slopes.len() != n_values {
            return Err(format!(
                "serialized state holds {} input slopes, this FMU has {n_values}",
                slopes.len()
            ));
        }
        let model_state = r.f64_array()?;
        if r.pos != body.len() {
            return Err(format!(
                "serialized state has {} trailing bytes",
                body.len() - r.pos
            ));
        }
        Ok(Snapshot {
            guid,
            state,
            initialized,
            time,
            values,
            sloped: slopes.iter().any(|s| *s != 0.0),
            slopes,
            model_state,
            parameters_version: u64::MAX,
        })
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|e| *e <= self.bytes.len())
            .ok_or_else(|| {
                format!(
                    "serialized state is truncated: needed {n} bytes at offset {}, {} left",
                    self.pos,
                    self.bytes.len() - self.pos
                )
            })?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64_array(&mut self) -> Result<Vec<f64>, String> {
        let n = self.u64()?;
        let left = (self.bytes.len() - self.pos) as u64 / 8;
        if n > left {
            return Err(format!(
                "serialized state declares {n} numbers but only {left} fit in the rest"
            ));
        }
        (0..n).map(|_| self.f64()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Snapshot {
        Snapshot {
            guid: "{g}",
            state: State::StepComplete,
            initialized: true,
            time: 1.5,
            values: vec![1.0, 2.0, f64::MIN_POSITIVE],
            slopes: vec![0.0, 0.5, 0.0],
            sloped: true,
            model_state: vec![3.0, -4.0],
            parameters_version: u64::MAX,
        }
    }

    #[test]
    fn round_trip_is_exact() {
        let s = sample();
        assert_eq!(Snapshot::from_bytes(&s.to_bytes(), "{g}", 3).unwrap(), s);
    }

    #[test]
    fn every_truncation_and_bit_flip_is_refused() {
        let bytes = sample().to_bytes();
        for n in 0..bytes.len() {
            assert!(
                Snapshot::from_bytes(&bytes[..n], "{g}", 3).is_err(),
                "truncated to {n}"
            );
        }
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(
                Snapshot::from_bytes(&b, "{g}", 3).is_err(),
                "bit flip at {i}"
            );
        }
    }

    #[test]
    fn foreign_guid_is_refused() {
        let err = Snapshot::from_bytes(&sample().to_bytes(), "{other}", 3).unwrap_err();
        assert!(err.contains("{g}"), "{err}");
    }
}
