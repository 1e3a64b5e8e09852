//! Which of Embree's code paths (instruction sets) a device runs: the best this CPU has, or the
//! one `REST_EMBREE_ISA` names (Embree's `isa=` device configuration), refused where the CPU
//! lacks it, since Embree would then die of an illegal instruction.
//!
//! The instruction set decides the packet width Embree traces natively (4 lanes for SSE, 8 for
//! AVX and AVX2, 16 for AVX-512); every other width is split and copied by Embree before it
//! calls back into user geometry, which is why the callbacks find their rays by id (exact.rs)
//! and why the tests run the backend under every instruction set the CPU has.

use crate::{Error, Result};

/// The environment variable that picks Embree's instruction set.
pub(crate) const ENV: &str = "REST_EMBREE_ISA";

/// One of Embree 3's code paths, named as its `isa=` configuration names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    Sse2,
    Sse42,
    Avx,
    Avx2,
    Avx512,
}

impl Isa {
    /// Every instruction set, oldest first.
    pub const ALL: [Isa; 5] = [Isa::Sse2, Isa::Sse42, Isa::Avx, Isa::Avx2, Isa::Avx512];

    /// The name `REST_EMBREE_ISA` and Embree's `isa=` take.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Sse2 => "sse2",
            Isa::Sse42 => "sse4.2",
            Isa::Avx => "avx",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The instruction set of that name.
    pub fn parse(name: &str) -> Result<Isa> {
        Isa::ALL
            .into_iter()
            .find(|i| i.name() == name.trim().to_ascii_lowercase())
            .ok_or_else(|| {
                Error::flag(
                    ENV,
                    format!(
                        "{name:?} is not an instruction set Embree knows (choose one of: {})",
                        names()
                    ),
                )
            })
    }

    /// Whether this CPU has every feature Embree's code path for it uses (Embree's own lists,
    /// `common/sys/sysinfo.h`: AVX2 with FMA, BMI1/2 and LZCNT; AVX-512 as SKX has it).
    pub fn on_this_cpu(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            match self {
                Isa::Sse2 => has!("sse2"),
                Isa::Sse42 => Isa::Sse2.on_this_cpu() && has!("sse4.2") && has!("popcnt"),
                Isa::Avx => Isa::Sse42.on_this_cpu() && has!("avx"),
                Isa::Avx2 => {
                    Isa::Avx.on_this_cpu()
                        && has!("avx2")
                        && has!("fma")
                        && has!("bmi1")
                        && has!("bmi2")
                        && has!("lzcnt")
                        && has!("f16c")
                }
                Isa::Avx512 => {
                    Isa::Avx2.on_this_cpu()
                        && has!("avx512f")
                        && has!("avx512dq")
                        && has!("avx512cd")
                        && has!("avx512bw")
                        && has!("avx512vl")
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// The instruction sets this CPU has, oldest first.
    pub fn on_cpu() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|i| i.on_this_cpu()).collect()
    }

    /// The best this CPU has (what Embree picks by itself), if any.
    pub fn best() -> Option<Isa> {
        Isa::on_cpu().last().copied()
    }

    /// The packet width this instruction set traces natively.
    pub fn native_width(self) -> usize {
        match self {
            Isa::Sse2 | Isa::Sse42 => 4,
            Isa::Avx | Isa::Avx2 => 8,
            Isa::Avx512 => 16,
        }
    }

    /// The instruction set `REST_EMBREE_ISA` asks for (None: unset or empty, Embree's own
    /// choice), refused if it is no instruction set or this CPU lacks it.
    pub fn from_env() -> Result<Option<Isa>> {
        match std::env::var(ENV) {
            Err(std::env::VarError::NotPresent) => Ok(None),
            Err(std::env::VarError::NotUnicode(v)) => Err(Error::flag(
                ENV,
                format!(
                    "{v:?} is not an instruction set Embree knows (choose one of: {})",
                    names()
                ),
            )),
            Ok(v) if v.trim().is_empty() => Ok(None),
            Ok(v) => Isa::parse(&v)?.checked().map(Some),
        }
    }

    /// This instruction set, if the CPU has it; else an error naming what it has.
    pub fn checked(self) -> Result<Isa> {
        self.checked_against(&Isa::on_cpu())
    }

    /// This instruction set, if it is among `has`; else an error naming those.
    fn checked_against(self, has: &[Isa]) -> Result<Isa> {
        if has.contains(&self) {
            return Ok(self);
        }
        let has: Vec<&str> = has.iter().map(|i| i.name()).collect();
        Err(Error::flag(
            ENV,
            format!(
                "this CPU does not have the instruction set {} (it has: {})",
                self.name(),
                if has.is_empty() {
                    "none of them".to_string()
                } else {
                    has.join(", ")
                }
            ),
        ))
    }
}

fn names() -> String {
    Isa::ALL.map(Isa::name).join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back_and_the_cpu_has_what_it_says() {
        for isa in Isa::ALL {
            assert_eq!(Isa::parse(isa.name()).unwrap(), isa);
            assert_eq!(Isa::parse(&isa.name().to_uppercase()).unwrap(), isa);
        }
        let e = Isa::parse("avx3").unwrap_err().to_string();
        assert!(e.contains("REST_EMBREE_ISA") && e.contains("sse4.2"), "{e}");
        let on = Isa::on_cpu();
        // Every x86-64 CPU has SSE2, and each set holds the ones below it.
        assert_eq!(on.first(), Some(&Isa::Sse2));
        assert_eq!(on, Isa::ALL[..on.len()].to_vec());
        for isa in Isa::ALL {
            assert_eq!(isa.checked().is_ok(), on.contains(&isa));
        }
        // An older CPU's refusal, whatever this one has.
        let old = [Isa::Sse2, Isa::Sse42];
        assert_eq!(Isa::Sse42.checked_against(&old).unwrap(), Isa::Sse42);
        let e = Isa::Avx2.checked_against(&old).unwrap_err().to_string();
        assert_eq!(
            e,
            "REST_EMBREE_ISA: this CPU does not have the instruction set avx2 (it has: sse2, sse4.2)"
        );
    }
}
