"""Pictures of an atlas store, from plain data to files:

* ``style`` -- colours, words and line styles of every type (shared by PNG and page);
* ``cells`` -- the cells, shares and coexistence of a store's levels, as plain data;
* ``diagram`` -- the delta-chi diagram (PNG); ``hodographs`` -- one run per type (PNG);
* ``page`` -- the self-contained interactive page (HTML);
* ``draw`` -- ``--plot PATH``: the three checked before any work and landed together.
"""
