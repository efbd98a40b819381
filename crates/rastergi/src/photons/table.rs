//! The photon map's slot table: open addressing with linear probing over a power-of-two
//! capacity at most half full, keyed by two words (cell index, plane key); the longest probe
//! of any key bounds every search. `table.wgsl` is its twin on the GPU.

use crate::sampling::pcg_hash;

/// A table entry without a slot.
pub const EMPTY: u32 = u32::MAX;

/// The hash of a slot key (`slot_hash` in `table.wgsl`).
fn slot_hash(cell: u32, plane: u32) -> u32 {
    pcg_hash(cell ^ pcg_hash(plane))
}

/// The slots of a map: keys (cell index, plane key) in an open-addressing table.
#[derive(Clone, Debug, PartialEq)]
pub struct SlotTable {
    /// `[cell, plane]` per entry, `[EMPTY, EMPTY]` where there is no slot; a power of two long.
    pub keys: Vec<[u32; 2]>,
    /// The longest probe sequence of any key: a search stops after this many entries.
    pub max_probe: u32,
}

impl SlotTable {
    /// A table holding `keys` (distinct), at most half full.
    pub fn new(keys: &[[u32; 2]]) -> SlotTable {
        let capacity = (2 * keys.len()).next_power_of_two().max(16);
        let mask = capacity as u32 - 1;
        let mut table = vec![[EMPTY; 2]; capacity];
        let mut max_probe = 1;
        for &k in keys {
            let mut i = slot_hash(k[0], k[1]) & mask;
            let mut probe = 1;
            while table[i as usize][0] != EMPTY {
                i = (i + 1) & mask;
                probe += 1;
            }
            table[i as usize] = k;
            max_probe = max_probe.max(probe);
        }
        SlotTable { keys: table, max_probe }
    }

    pub fn capacity(&self) -> usize {
        self.keys.len()
    }

    /// The entry of slot (cell, plane), if the map has it (`find_slot` in WGSL).
    pub fn find(&self, cell: u32, plane: u32) -> Option<usize> {
        let mask = self.keys.len() as u32 - 1;
        let mut i = slot_hash(cell, plane) & mask;
        for _ in 0..self.max_probe {
            let k = self.keys[i as usize];
            if k == [cell, plane] {
                return Some(i as usize);
            }
            if k[0] == EMPTY {
                return None;
            }
            i = (i + 1) & mask;
        }
        None
    }

    /// Entries holding a slot.
    pub fn len(&self) -> usize {
        self.keys.iter().filter(|k| k[0] != EMPTY).count()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_finds_every_key_it_holds_and_no_other() {
        let keys: Vec<[u32; 2]> = (0..5000u32).map(|i| [i * 7919 % 100_003, i % 13]).collect();
        let table = SlotTable::new(&keys);
        assert!(table.capacity() >= 2 * keys.len() && table.capacity().is_power_of_two());
        assert_eq!(table.len(), keys.len());
        let mut entries: Vec<usize> = keys.iter().map(|k| table.find(k[0], k[1]).expect("an inserted key")).collect();
        for (k, &e) in keys.iter().zip(&entries) {
            assert_eq!(table.keys[e], *k);
        }
        entries.sort_unstable();
        entries.dedup();
        assert_eq!(entries.len(), keys.len(), "two keys share an entry");
        for i in 0..5000u32 {
            assert_eq!(table.find(i * 7919 % 100_003, 13 + i % 5), None);
        }
    }
}
