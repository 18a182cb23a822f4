1LM=3
1.0 2.0
3 4
5.5 -6
IMAGE=skull_01.jpg
ID=skull_01
SCALE=0.5

LM=3
0 0
1 0
0 1
CURVES=1
POINTS=2
9 9
8 8
IMAGE=skull_02.jpg
ID=skull_02
