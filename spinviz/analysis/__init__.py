"""Analysis of finished runs: ``compare`` (the two models' predictions side by side), ``info``
(a body's derived quantities beside the figures the paper prints), ``detector`` and ``observe``
(what a detector and a stated ``receiver`` record, and when the models part: ``parting``), the
start-free power-frequency test (``pftest``), how long to watch (``decide``), the balances
(``balance``) and the sound (``sonify``)."""
