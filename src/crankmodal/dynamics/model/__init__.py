"""The mechanism model: bodies, ideal and clearance joints, loads, the assembled DAE and the builders of crank trains and four-bars."""
