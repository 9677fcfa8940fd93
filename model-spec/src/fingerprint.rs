//! A machine's fingerprint: a short, stable digest of what makes two descriptions the same
//! machine, for results and files that must be used with the machine they were made for.
//!
//! It covers, in this order:
//! - both chains, the work chain first, each from the bed outwards: every axis with its
//!   letter, type, direction, chain and offset; every fixed link with its offset; the end with
//!   its offset. An offset coordinate counts as its number (mm, `-0` as `0`) or its symbol's
//!   name;
//! - the names of the catalogue's errors in catalogue order, and the squareness order;
//! - the kinematic symbols in their order, each by name, and the default value (mm) of each
//!   **machine-side** symbol: every symbol except those of the workpiece set-up, that is the
//!   symbols used in the offset of the work chain's end and nowhere else
//!   ([`Machine::workpiece_symbols`]: `Xw Yw Zw` on `seed-ac`), because the ball is placed anew
//!   for every measurement.
//!
//! It leaves out what people read or choose per computation: the machine's name and
//! description, the names of links and ends, the strokes and ranges of the axes, the full
//! model (`[errors]` include and exclude) and the sub-models. A machine with a model appended
//! ([`crate::write::append_model`]) or with its ball moved has the same fingerprint.
//!
//! The digest is FNV-1a (64 bits) of a canonical encoding (strings with their length, numbers
//! by their IEEE 754 bits, little-endian), written as 16 lower-case hex digits. It does not
//! depend on the platform or the Rust version. The encoding starts with a version string, so a
//! change of the encoding changes every fingerprint.

use crate::machine::{AxisKind, Link, Machine, Offset, Side, SymbolId, Value};

/// Starts every encoding: changes when the encoding does.
const VERSION: &str = "rtest machine fingerprint 1";

/// FNV-1a, 64 bits.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn tag(&mut self, tag: u8) {
        self.bytes(&[tag]);
    }

    fn count(&mut self, n: usize) {
        self.bytes(&(n as u64).to_le_bytes());
    }

    fn str(&mut self, s: &str) {
        self.count(s.len());
        self.bytes(s.as_bytes());
    }

    fn number(&mut self, x: f64) {
        let x = if x == 0.0 { 0.0 } else { x };
        self.bytes(&x.to_bits().to_le_bytes());
    }

    fn offset(&mut self, m: &Machine, offset: &Offset) {
        for v in offset {
            match v {
                Value::Number(x) => {
                    self.tag(b'n');
                    self.number(*x);
                }
                Value::Symbol(s) => {
                    self.tag(b's');
                    self.str(&m.symbols[*s].name);
                }
            }
        }
    }
}

impl Machine {
    /// The symbols of the workpiece set-up: those used in the offset of the work chain's end
    /// and in no other offset (`Xw Yw Zw` on `seed-ac`), in symbol order.
    pub fn workpiece_symbols(&self) -> Vec<SymbolId> {
        let symbols = |offset: &Offset| -> Vec<SymbolId> {
            offset
                .iter()
                .filter_map(|v| match v {
                    Value::Symbol(s) => Some(*s),
                    Value::Number(_) => None,
                })
                .collect()
        };
        let mut elsewhere: Vec<SymbolId> = symbols(&self.tool.end_offset);
        for chain in [&self.work, &self.tool] {
            for link in &chain.links {
                match link {
                    Link::Axis(a) => elsewhere.extend(symbols(&self.axes[*a].offset)),
                    Link::Fixed { offset, .. } => elsewhere.extend(symbols(offset)),
                }
            }
        }
        let mut end = symbols(&self.work.end_offset);
        end.retain(|s| !elsewhere.contains(s));
        end.sort_unstable();
        end.dedup();
        end
    }

    /// The machine's fingerprint: 16 lower-case hex digits, stable across platforms and
    /// versions of rtest. See [`crate::fingerprint`] for what it covers and what it leaves out.
    pub fn fingerprint(&self) -> String {
        let mut h = Fnv::new();
        h.str(VERSION);
        for (side, chain) in [(Side::Work, &self.work), (Side::Tool, &self.tool)] {
            h.tag(match side {
                Side::Work => b'W',
                Side::Tool => b'T',
            });
            h.count(chain.links.len());
            for link in &chain.links {
                match link {
                    Link::Axis(i) => {
                        let a = &self.axes[*i];
                        h.tag(b'a');
                        h.str(&a.name);
                        h.tag(match a.kind {
                            AxisKind::Linear => b'L',
                            AxisKind::Rotary => b'R',
                        });
                        h.tag(a.direction.own.dir.index() as u8);
                        h.tag(u8::from(a.direction.own.negative));
                        if a.direction.inclined.is_some() {
                            h.tag(b'i');
                            for x in a.direction.unit() {
                                h.number(x);
                            }
                        }
                        h.tag(match a.side {
                            Side::Work => b'W',
                            Side::Tool => b'T',
                        });
                        h.offset(self, &a.offset);
                    }
                    Link::Fixed { offset, .. } => {
                        h.tag(b'f');
                        h.offset(self, offset);
                    }
                }
            }
            h.tag(b'e');
            h.offset(self, &chain.end_offset);
        }
        h.count(self.catalogue.len());
        for e in &self.catalogue {
            h.str(&e.name);
        }
        h.count(self.squareness_order.len());
        for &a in &self.squareness_order {
            h.str(&self.axes[a].name);
        }
        let workpiece = self.workpiece_symbols();
        h.count(self.symbols.len());
        for (i, s) in self.symbols.iter().enumerate() {
            h.str(&s.name);
            if workpiece.contains(&i) {
                h.tag(b'w');
            } else {
                h.tag(b'm');
                h.number(s.default);
            }
        }
        format!("{:016x}", h.0)
    }
}

#[cfg(test)]
mod tests {
    use super::Fnv;

    #[test]
    fn fnv1a_reference_values() {
        // The published test vectors of FNV-1a 64.
        let hash = |s: &str| {
            let mut h = Fnv::new();
            h.bytes(s.as_bytes());
            h.0
        };
        assert_eq!(hash(""), 0xcbf29ce484222325);
        assert_eq!(hash("a"), 0xaf63dc4c8601ec8c);
        assert_eq!(hash("foobar"), 0x85944171f73967e8);
    }
}
