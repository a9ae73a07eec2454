//! The state of each tracked frame (tracked, lost, recovered), as the loss detector
//! ([`super::loss`]) and the search again left it.

/// What happened to a tracked frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrameStatus {
    /// Tracked, fit as expected.
    #[default]
    Tracked,
    /// The fit fell: the track is lost (and the search again did not fit well enough).
    Lost,
    /// The track was lost and the search again found the body on this frame.
    Recovered,
}

impl FrameStatus {
    /// The word written in the run's CSV.
    pub fn word(self) -> &'static str {
        match self {
            FrameStatus::Tracked => "tracked",
            FrameStatus::Lost => "lost",
            FrameStatus::Recovered => "recovered",
        }
    }

    /// As a small number (checkpoints).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// From [`code`](Self::code).
    pub fn from_code(c: u8) -> Option<FrameStatus> {
        [
            FrameStatus::Tracked,
            FrameStatus::Lost,
            FrameStatus::Recovered,
        ]
        .get(c as usize)
        .copied()
    }
}
