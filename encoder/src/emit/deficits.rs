//! The deficit contexts of a level (SPEC §5.1, §5.5.5, format 3.3): the
//! replay writes each split's split-valence symbols in the contexts of
//! every choice, and the level keeps the choice whose two substreams code
//! smallest (a large level on its first eighth, as it does its plane and
//! wing policies). The symbols are the same under both; only their contexts, and
//! so the number of frequency tables, differ: on a small level the tables of
//! `valence` can cost more than its contexts save.

use splitstream_decoder_core::DeficitContexts;
use splitstream_decoder_core::context;
use splitstream_decoder_core::limits::substream;
use splitstream_decoder_core::writer::{StreamParams, SubstreamWriter, coded_len_in};

use super::policies::ranking_params;

/// One level's split-valence symbols in the contexts of every choice.
#[derive(Clone)]
pub struct DeficitCoding {
    /// Per choice of [`DeficitContexts::ALL`]: the deficit-p and deficit-c
    /// values, or `None` when the choice is ruled out.
    coded: [Option<[SubstreamWriter; 2]>; DeficitContexts::ALL.len()],
}

impl DeficitCoding {
    /// Every choice of `split-valences` (`split-history` is
    /// `every-vertex`'s, whose levels code no split valences and force
    /// their contexts), or only `forced`.
    pub fn new(forced: Option<DeficitContexts>) -> DeficitCoding {
        let used = |c: DeficitContexts| match forced {
            Some(f) => f == c,
            None => c != DeficitContexts::SplitHistory,
        };
        DeficitCoding {
            coded: DeficitContexts::ALL.map(|c| used(c).then(Default::default)),
        }
    }

    /// Records the symbols `sp` and `sc` of a split whose P and C have
    /// valences `valence_p` and `valence_c` right after it, and P's deficit
    /// `deficit_p` (SPEC §7.4).
    pub fn write(&mut self, sp: u8, sc: u8, deficit_p: u8, valence_p: usize, valence_c: usize) {
        for (contexts, coded) in DeficitContexts::ALL.into_iter().zip(&mut self.coded) {
            if let Some([p, c]) = coded {
                p.byte_in(context::deficit_p(contexts, valence_p), sp);
                c.byte_in(context::deficit_c(contexts, deficit_p, valence_c), sc);
            }
        }
    }

    /// Keeps only the cheapest choice so far (a large level's early
    /// choice, `policies::EARLY_CHOICE_SPLITS`): the rest of the level is
    /// written in its contexts only, and [`Self::choose`] has nothing left
    /// to weigh.
    pub fn choose_early(&mut self, params: &StreamParams) {
        let ranking = ranking_params(params);
        let best = DeficitContexts::ALL
            .into_iter()
            .zip(&mut self.coded)
            .filter_map(|(d, coded)| Some((cost(coded.as_mut()?, d, &ranking), d.to_byte())))
            .min();
        if let Some((_, best)) = best {
            for (d, coded) in DeficitContexts::ALL.into_iter().zip(&mut self.coded) {
                if d.to_byte() != best {
                    *coded = None;
                }
            }
        }
    }

    /// Puts the cheapest choice's substreams into `subs` (ids 1..=7 at
    /// 0..=6) and returns it; ties go to `plain`, which 3.2 decoders read.
    pub fn choose(self, subs: &mut [SubstreamWriter], params: &StreamParams) -> DeficitContexts {
        let ranking = ranking_params(params);
        let single = self.coded.iter().filter(|c| c.is_some()).count() == 1;
        let (_, contexts, [p, c]) = DeficitContexts::ALL
            .into_iter()
            .zip(self.coded)
            .filter_map(|(d, c)| c.map(|c| (d, c)))
            .map(|(d, mut coded)| {
                let cost = if single {
                    0
                } else {
                    cost(&mut coded, d, &ranking)
                };
                ((cost, d.to_byte()), d, coded)
            })
            .min_by_key(|&(key, ..)| key)
            .expect("at least one choice of deficit contexts");
        subs[(substream::DEFICIT_P - substream::FLAGS) as usize] = p;
        subs[(substream::DEFICIT_C - substream::FLAGS) as usize] = c;
        contexts
    }
}

/// Bytes a choice's deficit-p and deficit-c substreams take under the
/// ranking parameters (their rANS plans kept for framing, `coded_len_in`).
fn cost(
    [p, c]: &mut [SubstreamWriter; 2],
    contexts: DeficitContexts,
    ranking: &StreamParams,
) -> usize {
    coded_len_in(p, substream::DEFICIT_P, contexts, ranking)
        + coded_len_in(c, substream::DEFICIT_C, contexts, ranking)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Symbols that follow the valence (as real split valences do) make
    /// `valence` the cheaper choice once there are enough of them; a handful
    /// keep `plain`, whose single table costs less.
    #[test]
    fn the_choice_follows_the_cost() {
        let params = StreamParams::default();
        let pick = |n: usize| {
            let mut coding = DeficitCoding::new(None);
            for i in 0..n {
                let valence = 4 + i % 5;
                let symbol = (valence - 2 + (i / 5) % 2) as u8;
                coding.write(symbol, symbol, 1, valence, valence);
            }
            let mut subs = vec![SubstreamWriter::default(); 7];
            coding.choose(&mut subs, &params)
        };
        assert_eq!(pick(5), DeficitContexts::Plain);
        assert_eq!(pick(5000), DeficitContexts::Valence);
    }

    /// An early choice keeps the cheaper contexts of the symbols so far, and
    /// the level's substreams are then those that forcing it from the start
    /// writes.
    #[test]
    fn an_early_choice_codes_as_forcing_it() {
        let params = StreamParams::default();
        let symbols = |i: usize| {
            let valence = 4 + i % 5;
            ((valence - 2 + (i / 5) % 2) as u8, valence)
        };
        let (n, early_at) = (20_000, 2_500);
        let mut early = DeficitCoding::new(None);
        let mut forced = DeficitCoding::new(Some(DeficitContexts::Valence));
        for i in 0..n {
            if i == early_at {
                early.choose_early(&params);
                assert_eq!(early.coded.iter().filter(|c| c.is_some()).count(), 1);
            }
            let (symbol, valence) = symbols(i);
            early.write(symbol, symbol, 1, valence, valence);
            forced.write(symbol, symbol, 1, valence, valence);
        }
        let (mut a, mut b) = (
            vec![SubstreamWriter::default(); 7],
            vec![SubstreamWriter::default(); 7],
        );
        assert_eq!(early.choose(&mut a, &params), DeficitContexts::Valence);
        forced.choose(&mut b, &params);
        for k in [3, 4] {
            assert_eq!(a[k].symbols(), b[k].symbols());
        }
    }

    #[test]
    fn a_forced_choice_is_kept() {
        for forced in DeficitContexts::ALL {
            let mut coding = DeficitCoding::new(Some(forced));
            coding.write(5, 6, 1, 4, 5);
            let mut subs = vec![SubstreamWriter::default(); 7];
            assert_eq!(coding.choose(&mut subs, &StreamParams::default()), forced);
            assert_eq!(subs[3].symbols().len(), 1);
        }
    }
}
