//! Many groups of plain objects read on every thread. A scene of 100,000 groups spends most of
//! its build from the tree in the loop over its groups, one core's work; each group of boxes,
//! spheres or rods makes one group and one object per object table, so where every group is
//! such, each run of groups can be read on its own: its first group's index and its first
//! object's id are counted beforehand.
//!
//! Whatever this cannot settle on its own (an error anywhere, two groups of one name, the
//! primitive budget exceeded) sends the groups back to the one loop in `load.rs`, which reads
//! them again from fresh tables and reports the first error in file order; so the groups made
//! here are always the ones that loop makes, or none.

use super::load::group;
use super::model::{Group, Material, ObjectInfo};
use super::node::Val;
use super::reader::Table;
use rayon::prelude::*;
use std::collections::HashMap;

/// What groups make: the groups, their objects (in order) and their primitives.
type Read = (Vec<Group>, Vec<ObjectInfo>, u64);

/// Fewer groups than this are read in the one loop: splitting is not worth the threads.
const FROM: usize = 4096;
/// Groups read together, in order, by one task.
const PER_TASK: usize = 1024;
/// The object types whose groups are read here: one primitive each, nothing shared.
const PLAIN: [&str; 3] = ["box", "sphere", "rod"];

/// The number of object tables of each group, where there are many groups and every one is
/// plain: no worldline (one group each) and only [`PLAIN`] objects. None otherwise.
pub(super) fn plain(tables: &[Table]) -> Option<Vec<usize>> {
    if tables.len() < FROM || rayon::current_num_threads() < 2 {
        return None;
    }
    counts(tables)
}

/// The number of object tables of each group, where every group is plain.
fn counts(tables: &[Table]) -> Option<Vec<usize>> {
    tables
        .iter()
        .map(|t| {
            if t.has("worldline") {
                return None;
            }
            let Some(objects) = t.get("object") else {
                return Some(0);
            };
            let Val::Array(items) = &objects.val else {
                return None;
            };
            let plain = items.iter().all(|o| {
                let kind = o.entries().and_then(|e| e.iter().find(|(k, _)| k == "type"));
                matches!(kind, Some((_, n)) if matches!(&n.val, Val::Str(s) if PLAIN.contains(&s.as_str())))
            });
            plain.then_some(items.len())
        })
        .collect()
}

/// The groups of `tables` (whose object tables number `counts`), their objects and their
/// primitives, read in runs on every thread; None where the loop in `load.rs` must read them.
pub(super) fn read(
    tables: Vec<Table>,
    counts: &[usize],
    material_ids: &HashMap<String, u32>,
    materials: &[Material],
) -> Option<Read> {
    let n = tables.len();
    // Each run: its first group's index, its first object's id, its tables.
    let mut runs = Vec::with_capacity(n.div_ceil(PER_TASK));
    let mut tables = tables.into_iter();
    let (mut index, mut id) = (0, 0);
    while index < n {
        let run: Vec<Table> = tables.by_ref().take(PER_TASK).collect();
        let end = index + run.len();
        runs.push((index, id, run));
        id += counts[index..end].iter().sum::<usize>();
        index = end;
    }
    let read: Vec<Option<Read>> = runs
        .into_par_iter()
        .map(|(first, id_base, run)| {
            // Plain objects add no material; a copy shows if one did.
            let mut mats = materials.to_vec();
            let (mut groups, mut objects, mut total) = (Vec::with_capacity(run.len()), vec![], 0);
            let (mut imports, mut meshes) = Default::default();
            for (k, t) in run.iter().enumerate() {
                let name = t.req_string("name").ok()?;
                let ids = (&mut objects, id_base);
                let made = group(
                    t,
                    name,
                    material_ids,
                    &mut mats,
                    ids,
                    first + k,
                    &mut total,
                    &mut imports,
                    &mut meshes,
                )
                .ok()?;
                if made.len() != 1 {
                    return None;
                }
                groups.extend(made);
            }
            // The ids counted beforehand are the ids given: one object a table.
            let counted: usize = counts[first..first + run.len()].iter().sum();
            (mats.len() == materials.len() && objects.len() == counted)
                .then_some((groups, objects, total))
        })
        .collect();
    let (mut groups, mut objects, mut total) = (Vec::with_capacity(n), Vec::new(), 0u64);
    for run in read {
        let (g, o, t) = run?;
        groups.extend(g);
        objects.extend(o);
        total = total.saturating_add(t);
    }
    let distinct = {
        let mut names = hashbrown::HashSet::with_capacity(n);
        groups.iter().all(|g| names.insert(g.name.as_str()))
    };
    (distinct && super::objects::within_budget(total)).then_some((groups, objects, total))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::doc::Doc;

    /// `n` groups of boxes, spheres and rods, moving and at rest, named objects and not.
    fn scene(n: usize) -> String {
        let mut s = String::from(
            "[camera]\nposition = [0, -30, 0]\nlook_at = [0, 0, 0]\n[image]\nwidth = 8\nheight = 8\n\
             [[material]]\nname = \"red\"\ncolor = [1, 0, 0]\n",
        );
        for i in 0..n {
            let (x, x1) = ((i % 97) as f64 - 48.0, (i % 97) as f64 - 47.5);
            s += &format!("[[group]]\nname = \"g{i}\"\n");
            if i % 3 != 0 {
                s += &format!("velocity = [{}, 0, 0.1]\n", (i % 7) as f64 / 10.0);
            }
            s += &match i % 4 {
                0 => format!("[[group.object]]\ntype = \"box\"\nmin = [{x}, 0, 0]\nmax = [{x1}, 1, 1]\n"),
                1 => format!("[[group.object]]\ntype = \"sphere\"\nname = \"s{i}\"\ncenter = [{x}, 2, 0]\nradius = 0.3\nmaterial = \"red\"\n"),
                2 => format!("[[group.object]]\ntype = \"rod\"\nfrom = [{x}, 0, 0]\nto = [{x}, 0, 3]\nradius = 0.1\n[[group.object]]\ntype = \"box\"\nmin = [{x}, 5, 0]\nmax = [{x1}, 6, 1]\n"),
                _ => String::new(),
            };
        }
        s
    }

    /// The scene as `threads` threads load it: its bytes (as the render id hashes them), or
    /// its error.
    fn load(text: &str, threads: usize) -> Result<Vec<u8>, String> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
        pool.expect("a pool").install(|| {
            crate::scene::load_str("many.toml", text, &[])
                .map(|s| postcard::to_allocvec(&s).expect("a scene serializes"))
                .map_err(|e| e.to_string())
        })
    }

    /// The runs give the scene the one loop gives, byte for byte, and are used.
    #[test]
    fn many_plain_groups_read_as_the_one_loop_reads_them() {
        let text = scene(FROM + 300);
        let one = load(&text, 1);
        assert!(one.is_ok(), "{one:?}");
        assert_eq!(load(&text, 2), one);
        let doc = Doc::parse("many.toml", &text).expect("valid");
        let tables = Table::root(&doc)
            .and_then(|r| r.tables("group"))
            .expect("groups");
        let counts = counts(&tables).expect("plain groups");
        let expected: usize = (0..FROM + 300).map(|i| [1, 1, 2, 0][i % 4]).sum();
        assert_eq!(counts.iter().sum::<usize>(), expected);
        let mut ids = HashMap::new();
        ids.insert("red".to_string(), 1);
        let mats = [Material::default_white(), Material::default_white()];
        let (groups, objects, _) = read(tables, &counts, &ids, &mats).expect("read in runs");
        assert_eq!(
            (groups.len(), objects.len()),
            (FROM + 300, counts.iter().sum())
        );
    }

    /// An error anywhere, or two groups of one name, gives the one loop's first error.
    #[test]
    fn what_runs_cannot_settle_is_the_one_loops() {
        let text = scene(FROM + 10);
        let bad_object = text.replacen("radius = 0.3", "radius = -0.3", 700);
        let twice = text.replace("name = \"g4000\"", "name = \"g17\"");
        let unknown = text.replace("name = \"g2222\"", "name = \"g2222\"\nspeed = 3");
        for bad in [bad_object, twice, unknown] {
            let one = load(&bad, 1).expect_err("refused");
            assert_eq!(load(&bad, 2), Err(one));
        }
    }
}
