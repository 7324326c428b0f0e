//! Closed kinematic chains and cooperating arms (Freitas, Leite, Lizarralde 2010).
